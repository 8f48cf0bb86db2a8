// The self CCD's culling settings compared inside the simulator. Each setting runs its own
// Simulation of the same scene; the settings advance one frame each in turn, in an order that
// rotates every frame, so that whatever else loads the machine meanwhile is shared among them.
// The culling must not change the motion, so after every frame all settings' cloth positions
// and velocities are compared byte for byte (a difference is an error, not a figure).
#include "in_situ.hpp"

#include <fmt/format.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "clothcd/core/atomic_file.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/experiment/experiment.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/sim/simulation.hpp"

namespace clothcd::app {
namespace {

namespace fs = std::filesystem;
using namespace clothcd::sim;

struct Setting {
  const char* name;
  Culling culling;
  ConePolicy policy;
};
// PROVOT (index 1) is the reference of the ratios, as in the paper's tables.
constexpr std::array<Setting, 4> kSettings{{{"none", Culling::None, ConePolicy::Proposed},
                                            {"PROVOT", Culling::Sound, ConePolicy::Provot},
                                            {"PROPOSED", Culling::Sound, ConePolicy::Proposed},
                                            {"EXACT", Culling::Sound, ConePolicy::Exact}}};
constexpr std::size_t kProvot = 1;

// The paper's rule (the cone test alone, research::CullingRule::Cone) under PROVOT and under
// PROPOSED, counted on the steps of the simulator's full self CCD passes without changing them:
// the `none` setting's passes are copied as they start (ContactOptions::on_full_self_pass) and,
// after its frame, detected by a research detector of their own under no culling and both cone
// rules at once (detect_each: one narrow phase). Its tree is built on the first pass and rebuilt
// where its boxes loosen past 1.5 times their fit, as the simulator's (docs/simulator.md 3.6).
struct Shadow {
  static constexpr std::array<const char*, 2> kNames{"cone PROVOT", "cone PROPOSED"};
  std::vector<std::pair<std::vector<Vec3>, std::vector<Vec3>>> pending;
  std::optional<research::SelfDetector> det;
  std::vector<research::DetectOptions> configs;  // none, cone PROVOT, cone PROPOSED
  double fit = 0.0;
  long long calls = 0;
  std::array<long long, 3> pairs{}, culled{};  // totals, in configs' order
  // This frame's figures (the CSV's rows).
  long long frame_calls = 0;
  std::array<long long, 3> frame_pairs{}, frame_culled{};

  void count(const Simulation& sim) {
    frame_calls = 0;
    frame_pairs = frame_culled = {};
    for (const auto& [x0, x1] : pending) {
      if (!det) {
        const ContactOptions& c = sim.scene().contact;
        research::DetectOptions o;
        o.thickness = c.ccd_thickness;
        o.toi_tolerance = c.toi_tolerance;
        o.distance_filter_depth = c.distance_filter_depth;
        o.build = BvhBuild::Patch;  // the simulator's build
        configs.assign(3, o);
        for (int k = 1; k < 3; ++k)
          configs[k].research.culling = research::CullingRule::Cone;
        configs[1].policy = ConePolicy::Provot;
        configs[2].policy = ConePolicy::Proposed;
        det.emplace(sim.model().topology().faces(), sim.model().num_vertices(),
                    std::span<const Vec3>(x0), o);
      } else if (fit > 0.0 && det->bvh().box_area_ratio() > 1.5 * fit) {
        det->rebuild(std::span<const Vec3>(x0));
        fit = 0.0;
      }
      const std::vector<DetectResult> r =
          det->detect_each(std::span<const Vec3>(x0), std::span<const Vec3>(x1), configs);
      if (fit == 0.0) fit = det->bvh().box_area_ratio();
      ++frame_calls;
      for (std::size_t k = 0; k < 3; ++k) {
        frame_pairs[k] += static_cast<long long>(r[k].stats.triangle_pairs);
        frame_culled[k] += static_cast<long long>(r[k].stats.nodes_culled);
      }
    }
    pending.clear();
    calls += frame_calls;
    for (std::size_t k = 0; k < 3; ++k) {
      pairs[k] += frame_pairs[k];
      culled[k] += frame_culled[k];
    }
  }
};

// What one setting did on one scene.
struct Totals {
  int frames = 0;
  long long substeps = 0;
  SelfCcdFigures ccd;
  SelfProximityFigures proximity;
  std::vector<double> frame_seconds, collision_seconds;
};

struct SceneResult {
  std::string name;
  int faces = 0;
  std::array<Totals, kSettings.size()> totals;
  std::unique_ptr<Shadow> shadow = std::make_unique<Shadow>();
  std::vector<std::string> csv_rows;
};

fs::path source_dir() {
#ifdef CLOTHCD_SOURCE_DIR
  if (fs::exists(fs::path(CLOTHCD_SOURCE_DIR) / ".git")) return CLOTHCD_SOURCE_DIR;
#endif
  return fs::current_path();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool same_bytes(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

SceneResult run_scene(const fs::path& file, int frames) {
  SceneResult r;
  Shadow& shadow = *r.shadow;
  std::vector<std::unique_ptr<Simulation>> sims;
  for (const Setting& s : kSettings) {
    Scene scene = load_scene(file);
    if (!scene.collisions || !scene.contact.self) {
      throw input_error(file.string(), 0, "the scene has no cloth self contact to compare");
    }
    scene.contact.culling = s.culling;
    scene.contact.cone_policy = s.policy;
    scene.count_intersections = false;  // the same for every setting: left out of the times
    if (s.culling == Culling::None) {
      scene.contact.on_full_self_pass = [&shadow](std::span<const Vec3> x0,
                                                  std::span<const Vec3> x1) {
        shadow.pending.emplace_back(std::vector<Vec3>(x0.begin(), x0.end()),
                                    std::vector<Vec3>(x1.begin(), x1.end()));
      };
    }
    sims.push_back(std::make_unique<Simulation>(std::move(scene)));
  }
  r.name = sims[0]->scene().name;
  r.faces = static_cast<int>(sims[0]->model().topology().faces().size());
  const int n = std::min(frames, sims[0]->scene().frames);
  const std::size_t k = kSettings.size();
  for (int f = 0; f < n; ++f) {
    for (std::size_t j = 0; j < k; ++j) {
      const std::size_t i = (j + static_cast<std::size_t>(f)) % k;
      const FrameStats fs = sims[i]->advance_frame();
      if (!fs.finite) {
        throw std::runtime_error(fmt::format("{}: {} frame {} is not finite", file.string(),
                                             kSettings[i].name, fs.frame));
      }
      Totals& t = r.totals[i];
      ++t.frames;
      t.substeps += fs.substeps;
      t.ccd += fs.self_ccd;
      t.proximity += fs.self_proximity;
      t.frame_seconds.push_back(fs.seconds);
      t.collision_seconds.push_back(fs.collision.seconds);
      const SelfCcdFigures& c = fs.self_ccd;
      const SelfProximityFigures& p = fs.self_proximity;
      r.csv_rows.push_back(
          fmt::format("{},{},{},{},{:.6f},{:.6f},{},{},{},{:.6f},{:.6f},{:.6f},{},{},{},{:.6f}",
                      r.name, kSettings[i].name, fs.frame, fs.substeps, fs.seconds,
                      fs.collision.seconds, c.calls, c.triangle_pairs, c.nodes_culled, c.refit_s,
                      c.traversal_s, c.narrow_s, p.calls, p.reused_pairs, p.pairs, p.query_s));
      if (i != 0) continue;
      shadow.count(*sims[0]);  // after the frame: outside the simulator's times
      for (std::size_t k = 0; k < Shadow::kNames.size(); ++k) {
        r.csv_rows.push_back(fmt::format("{},{},{},{},0,0,{},{},{},0,0,0,0,0,0,0", r.name,
                                         Shadow::kNames[k], fs.frame, fs.substeps,
                                         shadow.frame_calls, shadow.frame_pairs[k + 1],
                                         shadow.frame_culled[k + 1]));
      }
    }
    for (std::size_t i = 1; i < k; ++i) {
      if (!same_bytes(sims[i]->state().x, sims[0]->state().x) ||
          !same_bytes(sims[i]->state().v, sims[0]->state().v)) {
        throw std::runtime_error(
            fmt::format("{}: frame {}: the cloth under {} differs from the cloth under {}: the "
                        "culling changed the motion",
                        file.string(), f + 1, kSettings[i].name, kSettings[0].name));
      }
    }
    fmt::print(stderr, "{}: frame {}/{} identical under all {} settings\n", r.name, f + 1, n, k);
  }
  return r;
}

double per_call(double total, long long calls) {
  return calls > 0 ? total / static_cast<double>(calls) : 0.0;
}

std::string ratio(double a, double b) {
  return b > 0.0 ? fmt::format("{:.3f}", a / b) : "-";
}

// Each setting against `none` per substep: the self-collision time (the full passes' CD time plus
// the proximity queries), what the cones cost (refit and traversal over none's) and what they
// save (narrow phase and proximity under none's), and the ratio the setting would reach were
// its refit and traversal as cheap as none's: how far the culling itself can take it.
std::string against_none(const SceneResult& r) {
  std::string md =
      "\nAgainst `none`, per substep (self-collision time = the full passes' CD time + the "
      "proximity queries; 'if cones were free': this setting's narrow phase and proximity with "
      "none's refit and traversal):\n\n"
      "| setting | self-collision ms / substep | vs none | cones' cost (refit + traversal "
      "over none's), ms | saved (narrow + proximity under none's), ms | vs none if cones were "
      "free |\n"
      "|---|---|---|---|---|---|\n";
  const auto ms = [](double s, long long substeps) { return 1e3 * per_call(s, substeps); };
  const Totals& none = r.totals[0];
  const double n_tests = ms(none.ccd.refit_s + none.ccd.traversal_s, none.substeps);
  const double n_rest = ms(none.ccd.narrow_s + none.proximity.query_s, none.substeps);
  for (std::size_t i = 0; i < kSettings.size(); ++i) {
    const Totals& t = r.totals[i];
    const double tests = ms(t.ccd.refit_s + t.ccd.traversal_s, t.substeps);
    const double rest = ms(t.ccd.narrow_s + t.proximity.query_s, t.substeps);
    md += fmt::format("| {} | {:.3f} | {} | {:.3f} | {:.3f} | {} |\n", kSettings[i].name,
                      tests + rest, ratio(tests + rest, n_tests + n_rest), tests - n_tests,
                      n_rest - rest, ratio(n_tests + rest, n_tests + n_rest));
  }
  return md;
}

std::string report(const InSituArgs& a, const std::vector<SceneResult>& results,
                   const std::string& header) {
  std::string md = header;
  md +=
      "Self-CCD figures are summed over each frame's full passes (the first CCD pass of every "
      "substep and any other pass that tests every pair); restricted passes, proximity queries "
      "and body contact are left out. CD time = refit + traversal + narrow phase of those "
      "calls. Proximity: the self proximity query at the start of every substep (it reuses the "
      "full pass's kept pairs where it can; nodes the cones culled hold none). Contact time is "
      "all contact handling of a frame (self and body, proximity, CCD passes, impact zones) and "
      "frame time the whole frame, medians over the frames. 'none' tests every node; the "
      "others are the sound culling with the given cones. Every frame's cloth positions and "
      "velocities were checked to be byte-identical across the four settings. 'cone PROVOT' and "
      "'cone PROPOSED' count what the paper's rule (a node's self test skipped wherever its cone "
      "is below pi/2, which can miss collisions) would test on the same full passes, detected "
      "aside by a detector of their own (its own tree, built and rebuilt as the simulator's) "
      "without changing the simulation; their ratios are to cone PROVOT, their 'pairs vs none' "
      "to that detector's unculled count.\n\n";
  md +=
      "Paper reference (Table 1-2, its own scenes and simulator): PROPOSED performs 0.75 of "
      "PROVOT's triangle pair tests and takes 0.82 of its CD time.\n";
  for (const SceneResult& r : results) {
    md += fmt::format("\n## {} ({} triangles)\n\n", r.name, r.faces);
    md +=
        "| setting | frames | substeps | self-CCD calls | pair tests / call | pairs vs none | "
        "nodes culled / call | refit ms / call | traversal ms / call | narrow ms / call | "
        "CD ms / call | proximity ms / call | contact s (median) | frame s (median) |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    const Totals& none = r.totals[0];
    for (std::size_t i = 0; i < kSettings.size(); ++i) {
      const Totals& t = r.totals[i];
      const long long c = t.ccd.calls;
      const double cd = t.ccd.refit_s + t.ccd.traversal_s + t.ccd.narrow_s;
      md += fmt::format(
          "| {} | {} | {} | {} | {:.0f} | {} | {:.0f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | "
          "{:.3f} | {:.3f} | {:.3f} |\n",
          kSettings[i].name, t.frames, t.substeps, c,
          per_call(static_cast<double>(t.ccd.triangle_pairs), c),
          ratio(static_cast<double>(t.ccd.triangle_pairs),
                static_cast<double>(none.ccd.triangle_pairs)),
          per_call(static_cast<double>(t.ccd.nodes_culled), c), 1e3 * per_call(t.ccd.refit_s, c),
          1e3 * per_call(t.ccd.traversal_s, c), 1e3 * per_call(t.ccd.narrow_s, c),
          1e3 * per_call(cd, c), 1e3 * per_call(t.proximity.query_s, t.proximity.calls),
          median(t.collision_seconds), median(t.frame_seconds));
    }
    const Shadow& sh = *r.shadow;
    for (std::size_t k = 0; k < Shadow::kNames.size(); ++k) {
      md +=
          fmt::format("| {} | {} | {} | {} | {:.0f} | {} | {:.0f} | - | - | - | - | - | - | - |\n",
                      Shadow::kNames[k], none.frames, none.substeps, sh.calls,
                      per_call(static_cast<double>(sh.pairs[k + 1]), sh.calls),
                      ratio(static_cast<double>(sh.pairs[k + 1]), static_cast<double>(sh.pairs[0])),
                      per_call(static_cast<double>(sh.culled[k + 1]), sh.calls));
    }
    md +=
        "\nRatios to PROVOT (per call; paper: PROPOSED 0.75 of the pair tests, 0.82 of the CD "
        "time):\n\n"
        "| setting | pair tests | nodes culled | refit | traversal | narrow | CD time | "
        "proximity | contact (median) | frame (median) | paper pair tests | paper CD time |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    const Totals& p = r.totals[kProvot];
    const long long pc = p.ccd.calls;
    for (std::size_t i = 0; i < kSettings.size(); ++i) {
      const Totals& t = r.totals[i];
      const long long c = t.ccd.calls;
      auto rel = [&](double ours, double theirs) {
        return ratio(per_call(ours, c), per_call(theirs, pc));
      };
      const bool proposed =
          kSettings[i].policy == ConePolicy::Proposed && kSettings[i].culling == Culling::Sound;
      const bool provot = i == kProvot;
      md += fmt::format(
          "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", kSettings[i].name,
          rel(static_cast<double>(t.ccd.triangle_pairs), static_cast<double>(p.ccd.triangle_pairs)),
          rel(static_cast<double>(t.ccd.nodes_culled), static_cast<double>(p.ccd.nodes_culled)),
          rel(t.ccd.refit_s, p.ccd.refit_s), rel(t.ccd.traversal_s, p.ccd.traversal_s),
          rel(t.ccd.narrow_s, p.ccd.narrow_s),
          rel(t.ccd.refit_s + t.ccd.traversal_s + t.ccd.narrow_s,
              p.ccd.refit_s + p.ccd.traversal_s + p.ccd.narrow_s),
          ratio(per_call(t.proximity.query_s, t.proximity.calls),
                per_call(p.proximity.query_s, p.proximity.calls)),
          ratio(median(t.collision_seconds), median(p.collision_seconds)),
          ratio(median(t.frame_seconds), median(p.frame_seconds)),
          proposed ? "0.75"
          : provot ? "1"
                   : "",
          proposed ? "0.82"
          : provot ? "1"
                   : "");
    }
    // The paper's rule against itself: cone PROPOSED over cone PROVOT, on the same passes.
    for (std::size_t k = 0; k < Shadow::kNames.size(); ++k) {
      md += fmt::format(
          "| {} | {} | {} | - | - | - | - | - | - | - | {} | - |\n", Shadow::kNames[k],
          ratio(static_cast<double>(sh.pairs[k + 1]), static_cast<double>(sh.pairs[1])),
          ratio(static_cast<double>(sh.culled[k + 1]), static_cast<double>(sh.culled[1])),
          k == 0 ? "1" : "0.75");
    }
    md += against_none(r);
  }
  (void)a;
  return md;
}

}  // namespace

int run_in_situ(const InSituArgs& a) {
  if (a.tables_only) {
    if (a.out.empty()) throw InputError("--in-situ-tables: --out (the results folder) is required");
    const fs::path folder =
        fs::path(a.out).extension() == ".md" ? fs::path(a.out).parent_path() : fs::path(a.out);
    if (!fs::exists(folder / "in_situ.csv")) {
      throw InputError(fmt::format("--in-situ-tables: no in_situ.csv in '{}'", folder.string()));
    }
    for (const fs::path& t : experiment::update_in_situ_sections(folder))
      fmt::print("rewrote the in-situ section of {}\n", t.string());
    return 0;
  }
  if (a.scenes.empty()) throw InputError("--in-situ: no scene files given");
  if (a.frames < 1) throw InputError("--frames: at least 1 frame");
  // SCENE@N: at most N frames of that scene.
  std::vector<std::pair<std::string, int>> scenes;
  for (const auto& s : a.scenes) {
    std::string file = s;
    int frames = a.frames;
    if (const auto at = s.rfind('@'); at != std::string::npos && !fs::exists(s)) {
      file = s.substr(0, at);
      try {
        std::size_t used = 0;
        frames = std::min(frames, std::stoi(s.substr(at + 1), &used));
        if (used != s.size() - at - 1 || frames < 1) throw std::invalid_argument(s);
      } catch (const std::logic_error&) {
        throw InputError(fmt::format("--in-situ: '{}': expected SCENE@FRAMES, FRAMES >= 1", s));
      }
    }
    if (!fs::is_regular_file(file)) {
      throw InputError(fmt::format("--in-situ: no scene file '{}'", file));
    }
    scenes.emplace_back(file, frames);
  }
  fs::path md_path = a.out.empty() ? fs::path("docs/results/in_situ.md") : fs::path(a.out);
  if (fs::is_directory(md_path) || md_path.extension() != ".md") md_path /= "in_situ.md";
  fs::path csv_path = md_path;
  csv_path.replace_extension(".csv");
  std::optional<tbb::global_control> limit;
  if (a.threads > 0) {
    limit.emplace(tbb::global_control::max_allowed_parallelism,
                  static_cast<std::size_t>(a.threads));
  }
  const std::string load_before = experiment::load_average();
  const std::string date = experiment::utc_now();
  // The report is rewritten after every scene, so a run cut short keeps the scenes it finished.
  std::vector<SceneResult> results;
  for (const auto& [file, frames] : scenes) {
    results.push_back(run_scene(file, frames));
    const std::string header = fmt::format(
        "# Self-CCD culling in situ\n\n"
        "- command: `{}`\n"
        "- commit: {}\n"
        "- machine: {} cores ({}), {} worker threads\n"
        "- date: {}\n"
        "- load average (1, 5, 15 min): {} before, {} after\n"
        "- scenes: {} of {} done\n"
        "- per-frame figures: {}\n\n",
        a.command, experiment::git_commit(source_dir()), ::sysconf(_SC_NPROCESSORS_ONLN),
        experiment::cpu_model(), a.threads > 0 ? fmt::format("{}", a.threads) : std::string("all"),
        date, load_before, experiment::load_average(), results.size(), scenes.size(),
        csv_path.filename().string());
    std::string csv =
        "scene,setting,frame,substeps,frame_s,collision_s,self_ccd_calls,triangle_pairs,"
        "nodes_culled,refit_s,traversal_s,narrow_s,proximity_calls,proximity_reused_pairs,"
        "proximity_pairs,proximity_s\n";
    for (const SceneResult& r : results) {
      for (const auto& row : r.csv_rows)
        csv += row + "\n";
    }
    if (!md_path.parent_path().empty()) fs::create_directories(md_path.parent_path());
    write_file_atomic(csv_path, csv);
    write_file_atomic(md_path, report(a, results, header));
  }
  // The tables read in_situ.csv: only a report of that name is theirs.
  if (md_path.filename() == "in_situ.md") {
    for (const fs::path& t : experiment::update_in_situ_sections(
             md_path.parent_path().empty() ? fs::path(".") : md_path.parent_path())) {
      fmt::print("rewrote the in-situ section of {}\n", t.string());
    }
  }
  fmt::print("results in {} and {}\n", md_path.string(), csv_path.string());
  return 0;
}

}  // namespace clothcd::app
