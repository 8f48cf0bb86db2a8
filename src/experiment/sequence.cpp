// Recorded motion for the experiment: frame folders, simulated scenes, procedural sequences.
#include "clothcd/experiment/sequence.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <numbers>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/research/procedural.hpp"
#include "clothcd/sim/frame_io.hpp"
#include "clothcd/sim/intersections.hpp"
#include "clothcd/sim/scene.hpp"
#include "clothcd/sim/simulation.hpp"

namespace clothcd::experiment {
namespace {

namespace fs = std::filesystem;

bool is_mesh_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".obj" || ext == ".ply";
}

// The number at the end of a file stem ("cloth_ball92" -> 92, "frame_0007" -> 7), -1 if none.
long trailing_number(const fs::path& p) {
  const std::string stem = p.stem().string();
  std::size_t i = stem.size();
  while (i > 0 && std::isdigit(static_cast<unsigned char>(stem[i - 1])) != 0)
    --i;
  if (i == stem.size()) return -1;
  return std::stol(stem.substr(i, std::min<std::size_t>(stem.size() - i, 15)));
}

std::string sanitize(std::string s) {
  for (char& c : s) {
    if (std::isalnum(static_cast<unsigned char>(c)) == 0 && c != '-' && c != '_' && c != '.') {
      c = '-';
    }
  }
  return s.empty() ? std::string("scene") : s;
}

std::vector<fs::path> frame_files(const fs::path& dir, int max_frames,
                                  std::vector<long long>* crossings) {
  std::vector<fs::path> files;
  const fs::path manifest = dir / "manifest.json";
  if (fs::exists(manifest)) {
    // The simulator's folder: only frames the manifest commits to (a later one may be partial).
    nlohmann::json m;
    try {
      std::ifstream in(manifest);
      m = nlohmann::json::parse(in);
      const int complete = m.at("complete_frames").get<int>();
      const std::string ext = m.at("mesh_format").get<std::string>();
      for (int k = 0; k <= complete; ++k)
        files.push_back(dir / fmt::format("frame_{:04d}.{}", k, ext));
      // The simulator's own count of each frame's self-crossing pairs (seam-linked pairs
      // skipped); left empty when a frame lacks it, so the caller counts instead.
      std::vector<long long> c(files.size(), -1);
      if (m.contains("initial_self_intersections"))
        c[0] = m["initial_self_intersections"].get<long long>();
      for (const auto& f : m.value("frames", nlohmann::json::array())) {
        const int k = f.value("frame", -1);
        if (k >= 0 && k < static_cast<int>(c.size()) && f.contains("self_intersections"))
          c[static_cast<std::size_t>(k)] = f["self_intersections"].get<long long>();
      }
      if (std::find(c.begin(), c.end(), -1) == c.end()) *crossings = std::move(c);
    } catch (const nlohmann::json::exception& e) {
      throw input_error(manifest.string(), 0, fmt::format("unreadable manifest: {}", e.what()));
    }
  } else {
    for (const auto& e : fs::directory_iterator(dir)) {
      if (e.is_regular_file() && is_mesh_file(e.path())) files.push_back(e.path());
    }
    std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
      const long na = trailing_number(a), nb = trailing_number(b);
      return na != nb ? na < nb : a.filename() < b.filename();
    });
  }
  if (max_frames >= 0 && static_cast<int>(files.size()) > max_frames) files.resize(max_frames);
  if (crossings->size() > files.size()) crossings->resize(files.size());
  return files;
}

Positions to_positions(const std::vector<Eigen::Vector3d>& x) {
  Positions p(static_cast<Eigen::Index>(x.size()), 3);
  for (std::size_t i = 0; i < x.size(); ++i)
    p.row(static_cast<Eigen::Index>(i)) = x[i].transpose();
  return p;
}

Sequence one_step(const research::ProceduralScene& s) {
  Sequence q;
  q.name = s.name;
  q.source = "procedural: " + s.name + " (clothcd/research/procedural.hpp, one step)";
  q.faces = s.faces;
  q.num_vertices = s.num_vertices;
  q.frames = {s.v_t0, s.v_t1};
  return q;
}

}  // namespace

Sequence load_frame_folder(const fs::path& dir, int max_frames, std::string name) {
  if (!fs::is_directory(dir)) throw input_error(dir.string(), 0, "not a folder of frames");
  std::vector<long long> crossings;
  const auto files = frame_files(dir, max_frames, &crossings);
  if (files.size() < 2) {
    throw input_error(dir.string(), 0,
                      "expected at least two frames (manifest.json + frame_NNNN.obj|ply, or "
                      ".obj/.ply files numbered at the end of their names)");
  }
  Sequence seq;
  seq.name =
      sanitize(name.empty() ? fs::absolute(dir).lexically_normal().filename().string() : name);
  if (seq.name == "frames" || seq.name.empty()) {
    seq.name = sanitize(fs::absolute(dir).lexically_normal().parent_path().filename().string());
  }
  seq.source = fmt::format("{} ({} .. {})", dir.string(), files.front().filename().string(),
                           files.back().filename().string());
  TriangleMesh first = read_mesh(files.front());
  validate_mesh(first, files.front().string());
  seq.faces = first.faces;
  seq.num_vertices = first.num_vertices();
  seq.frames.push_back(to_positions(first.vertices));
  for (std::size_t k = 1; k < files.size(); ++k) {
    TriangleMesh m = read_mesh(files[k]);
    check_same_topology(first, files.front(), m, files[k]);
    validate_mesh(m, files[k].string());
    seq.frames.push_back(to_positions(m.vertices));
  }
  if (!crossings.empty()) {
    seq.crossings = std::move(crossings);
    seq.crossings_how = "the simulator's check (manifest.json; stitched pairs skipped)";
  }
  return seq;
}

void count_crossings(Sequence& seq) {
  if (seq.crossings.size() == seq.frames.size()) return;
  Topology topo(seq.faces, seq.num_vertices);
  sim::IntersectionCounter counter(topo, {}, {}, 0);
  seq.crossings.clear();
  std::vector<sim::Vec3> x;
  for (const Positions& p : seq.frames) {
    x.resize(static_cast<std::size_t>(p.rows()));
    for (Eigen::Index i = 0; i < p.rows(); ++i)
      x[static_cast<std::size_t>(i)] = p.row(i).transpose();
    seq.crossings.push_back(static_cast<long long>(counter.self_pairs(x).size()));
  }
  seq.crossings_how = "clothcd's intersection check (sim/intersections.hpp)";
}

void drop_frames_before(Sequence& seq, int first) {
  if (first <= 0) return;
  const auto n = std::min<std::size_t>(static_cast<std::size_t>(first), seq.frames.size());
  seq.frames.erase(seq.frames.begin(), seq.frames.begin() + static_cast<std::ptrdiff_t>(n));
  if (seq.crossings.size() >= n) {
    seq.crossings.erase(seq.crossings.begin(),
                        seq.crossings.begin() + static_cast<std::ptrdiff_t>(n));
  }
}

Sequence simulate_scene(const fs::path& scene_file, const fs::path& out, int frames,
                        const std::function<void(int, int)>& on_frame) {
  sim::Simulation simulation(sim::load_scene(scene_file));
  const int total = frames >= 0 ? frames : simulation.scene().frames;
  sim::RunOptions opt;
  opt.out = out;
  opt.frames = total;
  // Reuses what an earlier run left (resume continues bitwise identically from its last frame).
  opt.resume = fs::exists(out / "manifest.json");
  if (on_frame) opt.on_frame = [&](const sim::FrameStats& s, int t) { on_frame(s.frame, t); };
  if (opt.resume) {
    std::ifstream in(out / "manifest.json");
    int done = -1;
    try {
      done = nlohmann::json::parse(in).at("complete_frames").get<int>();
    } catch (const nlohmann::json::exception&) {
      done = -1;  // run_simulation reports the unreadable manifest
    }
    // A longer recording is simply cut: simulating never shortens it.
    if (done >= total) return load_frame_folder(out, total + 1, simulation.scene().name);
  }
  (void)sim::run_simulation(simulation, opt);
  Sequence seq = load_frame_folder(out, total + 1, simulation.scene().name);
  seq.source =
      fmt::format("{} simulated into {} (frames 0..{})", scene_file.string(), out.string(), total);
  return seq;
}

Sequence folding_sheet(int n, int steps) {
  if (n < 2 || steps < 1) throw InputError("folding_sheet: n >= 2 and steps >= 1 expected");
  Sequence seq;
  seq.name = "fold";
  seq.source = fmt::format("procedural: {0} x {0} folding sheet, {1} steps", n, steps);
  seq.num_vertices = (n + 1) * (n + 1);
  auto id = [n](int i, int j) { return i * (n + 1) + j; };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      // Alternating diagonals keep the mesh free of a preferred direction.
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0) {
        seq.faces.push_back({a, b, c});
        seq.faces.push_back({a, c, d});
      } else {
        seq.faces.push_back({a, b, d});
        seq.faces.push_back({b, c, d});
      }
    }
  }
  constexpr double kPi = std::numbers::pi;
  const double amp = 0.6 / n;  // ripple amplitude: larger than the layer gap, so layers cross
  const int fold_steps = std::max(1, steps / 2);
  for (int k = 0; k <= steps; ++k) {
    const double theta = kPi * std::min(1.0, double(k) / fold_steps);
    // The far half's ripple is a quarter wave off the near half's (so the closed fold is not two
    // coincident layers) and travels once the fold is closed; the near half's stays.
    const double phase = 0.25 + 0.17 * std::max(0, k - fold_steps);
    Positions p(seq.num_vertices, 3);
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) {
        const double x = double(i) / n - 0.5, z = double(j) / n;
        const bool far = x > 0;
        const double ph = far ? phase : 0.0;
        // The far ripple fades in from the fold line, so the sheet stays continuous there.
        const double fade = far ? std::min(1.0, x / 0.1) : 1.0;
        const double y =
            fade * amp * std::sin(2 * kPi * (1.5 * x + ph)) * std::sin(2 * kPi * 1.25 * z);
        // Rotate the far half about the z axis through the middle line (x = 0).
        const double px = far ? x * std::cos(theta) - y * std::sin(theta) : x;
        const double py = far ? x * std::sin(theta) + y * std::cos(theta) : y;
        p.row(id(i, j)) << px, py, z;
      }
    }
    seq.frames.push_back(std::move(p));
  }
  return seq;
}

std::vector<std::string> procedural_names() {
  return {"fold", "stacked_sheets", "winding_strip", "crumpled_sheet", "twisted_strip"};
}

Sequence procedural_sequence(const std::string& name) {
  if (name == "fold") return folding_sheet(40, 12);
  if (name == "stacked_sheets") return one_step(research::stacked_sheets());
  if (name == "winding_strip") return one_step(research::winding_strip());
  if (name == "crumpled_sheet") return one_step(research::crumpled_sheet(48, 7));
  if (name == "twisted_strip") return one_step(research::twisted_strip());
  std::string names;
  for (const auto& n : procedural_names())
    names += (names.empty() ? "" : ", ") + n;
  throw InputError(
      fmt::format("unknown procedural sequence '{}' (expected one of: {})", name, names));
}

}  // namespace clothcd::experiment
