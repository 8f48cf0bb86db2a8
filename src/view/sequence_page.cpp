// The page of a simulation: the manifest's figures, the cloth (and the body) at every chosen
// frame, the cloth's rest shape for the strain colouring and per-frame contact flags.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <memory>
#include <optional>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/sim/cloth_model.hpp"
#include "clothcd/sim/scene.hpp"
#include "clothcd/view/page.hpp"
#include "view/page_builder.hpp"
#include "view/quantize.hpp"

namespace clothcd::view {
namespace {

namespace fs = std::filesystem;
using detail::DataBlock;

nlohmann::json read_manifest(const fs::path& file) {
  std::ifstream in(file);
  if (!in) {
    throw input_error(file.string(), 0,
                      "cannot open (expected the output folder of `clothcd simulate`)");
  }
  nlohmann::json m;
  try {
    m = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw input_error(file.string(), 0, fmt::format("invalid JSON: {}", e.what()));
  }
  auto need = [&](const char* key, auto check, const char* what) {
    if (!m.is_object() || !m.contains(key) || !check(m.at(key))) {
      throw input_error(file.string(), 0, fmt::format("'{}' missing or not {}", key, what));
    }
  };
  need(
      "complete_frames", [](const auto& v) { return v.is_number_integer() && v >= 0; },
      "a non-negative integer");
  need(
      "frames", [](const auto& v) { return v.is_array(); }, "an array");
  need(
      "frame_dt", [](const auto& v) { return v.is_number() && v > 0; }, "a positive number");
  need(
      "mesh_format", [](const auto& v) { return v == "obj" || v == "ply"; }, "\"obj\" or \"ply\"");
  for (const auto& f : m.at("frames")) {
    if (!f.is_object() || !f.contains("frame") || !f.at("frame").is_number_integer()) {
      throw input_error(file.string(), 0, "an entry of 'frames' has no integer 'frame'");
    }
  }
  return m;
}

// The top-level figures the page shows beside the frames.
nlohmann::json run_summary(const nlohmann::json& m) {
  nlohmann::json s = nlohmann::json::object();
  for (const char* key :
       {"scene", "vertices", "faces", "frame_dt", "slivers", "stitches", "collisions",
        "complete_frames", "initial_self_intersections", "initial_body_intersections"}) {
    if (m.contains(key)) s[key] = m.at(key);
  }
  if (m.contains("contact") && m.at("contact").contains("thickness"))
    s["thickness"] = m.at("contact").at("thickness");
  return s;
}

// Per frame: the figures of the manifest's frame entry (none for frame 0).
nlohmann::json frame_figures(const nlohmann::json& m, int frame) {
  for (const auto& f : m.at("frames")) {
    if (f.at("frame").get<int>() != frame) continue;
    nlohmann::json out = nlohmann::json::object();
    for (const char* key : {"time", "substeps", "halvings", "pcg_iterations", "ccd_hits",
                            "proximity_pairs", "zones", "unresolved_ccd_hits", "self_intersections",
                            "body_intersections", "max_stretch", "seconds", "collision_seconds"}) {
      if (f.contains(key)) out[key] = f.at(key);
    }
    return out;
  }
  nlohmann::json out = {{"time", 0.0}};
  if (m.contains("initial_self_intersections"))
    out["self_intersections"] = m.at("initial_self_intersections");
  if (m.contains("initial_body_intersections"))
    out["body_intersections"] = m.at("initial_body_intersections");
  return out;
}

std::vector<std::uint32_t> flat_faces(const std::vector<Face>& faces) {
  std::vector<std::uint32_t> out;
  out.reserve(faces.size() * 3);
  for (const Face& f : faces)
    for (int k = 0; k < 3; ++k)
      out.push_back(static_cast<std::uint32_t>(f[k]));
  return out;
}

void add_mesh(DataBlock& block, nlohmann::json& meshes, const std::string& name,
              const std::vector<Face>& faces, const std::vector<std::vector<Vec3>>& frames) {
  const detail::QuantizedFrames q = detail::quantize_frames(frames);
  block.add(name + "_faces", std::span<const std::uint32_t>(flat_faces(faces)));
  block.add(name + "_low", std::span<const std::uint8_t>(q.low));
  block.add(name + "_high", std::span<const std::uint8_t>(q.high));
  meshes[name] = {{"vertices", frames.front().size()},
                  {"faces", faces.size()},
                  {"origin", q.origin},
                  {"step", q.step}};
}

// Vertices within `h` of another, non-neighbouring part of the cloth or of the body, per frame,
// one bit per vertex (LSB first).
std::vector<std::uint8_t> contact_flags(const std::vector<Face>& faces,
                                        const std::vector<std::vector<Vec3>>& cloth,
                                        const std::vector<Face>* body_faces,
                                        const std::vector<std::vector<Vec3>>& body, double h,
                                        const std::vector<std::pair<int, int>>& links) {
  const int n = static_cast<int>(cloth.front().size());
  const std::size_t row = (static_cast<std::size_t>(n) + 7) / 8;
  std::vector<std::uint8_t> bits(row * cloth.size(), 0);
  DetectOptions opt;
  opt.linked_vertices = links;
  SelfDetector self(faces, n, std::span<const Vec3>(cloth.front()), opt);
  std::optional<PairDetector> pair;
  if (body_faces != nullptr) {
    pair.emplace(faces, n, std::span<const Vec3>(cloth.front()), *body_faces,
                 static_cast<int>(body.front().size()), std::span<const Vec3>(body.front()),
                 DetectOptions{});
  }
  const auto& edges = self.topology().edges();
  for (std::size_t k = 0; k < cloth.size(); ++k) {
    std::uint8_t* r = bits.data() + k * row;
    auto mark = [r](int v) { r[v >> 3] |= static_cast<std::uint8_t>(1u << (v & 7)); };
    const ProximityResult p = self.proximity(std::span<const Vec3>(cloth[k]), h);
    for (const auto& c : p.vf) {
      mark(c.vertex);
      for (int v : faces[c.face])
        mark(v);
    }
    for (const auto& c : p.ee) {
      for (int e : {c.edge_a, c.edge_b}) {
        mark(edges[e][0]);
        mark(edges[e][1]);
      }
    }
    if (pair) {
      const PairProximityResult b =
          pair->proximity(std::span<const Vec3>(cloth[k]), std::span<const Vec3>(body[k]), h);
      for (const auto& c : b.vf_a_on_b)
        mark(c.vertex);
      for (const auto& c : b.vf_b_on_a)
        for (int v : faces[c.face])
          mark(v);
      const auto& cloth_edges = pair->topology_a().edges();
      for (const auto& c : b.ee) {
        mark(cloth_edges[c.edge_a][0]);
        mark(cloth_edges[c.edge_a][1]);
      }
    }
  }
  return bits;
}

}  // namespace

PageSummary write_sequence_page(const fs::path& folder, const fs::path& out,
                                const SequenceOptions& opt) {
  const fs::path manifest_path = folder / "manifest.json";
  if (!fs::is_directory(folder)) {
    throw input_error(folder.string(), 0,
                      "not a folder (expected the output folder of `clothcd simulate`)");
  }
  const nlohmann::json m = read_manifest(manifest_path);
  const int complete = m.at("complete_frames").get<int>();
  const int last = opt.last < 0 ? complete : opt.last;
  if (opt.first < 0 || opt.first > last || last > complete || opt.step < 1) {
    throw input_error(manifest_path.string(), 0,
                      fmt::format("frames {}..{} step {} are not within the complete frames 0..{}",
                                  opt.first, last, opt.step, complete));
  }
  const std::string ext = m.at("mesh_format").get<std::string>();
  std::vector<int> frames;
  for (int f = opt.first; f <= last; f += opt.step)
    frames.push_back(f);
  if (frames.back() != last) frames.push_back(last);
  std::vector<fs::path> files;
  for (int f : frames) {
    files.push_back(folder / fmt::format("frame_{:04d}.{}", f, ext));
    if (!fs::exists(files.back())) {
      throw input_error(
          files.back().string(), 0,
          fmt::format("missing (the manifest says frames 0..{} are complete)", complete));
    }
  }
  PageSummary summary;
  std::vector<std::vector<Vec3>> cloth;
  std::vector<Face> faces;
  for (std::size_t i = 0; i < files.size(); ++i) {
    TriangleMesh mesh = read_mesh(files[i]);
    if (i == 0) {
      faces = mesh.faces;
    } else if (mesh.vertices.size() != cloth.front().size() || mesh.faces != faces) {
      throw input_error(files[i].string(), 0,
                        fmt::format("topology differs from {} ({} vertices, {} faces here; {} "
                                    "and {} there)",
                                    files.front().string(), mesh.vertices.size(), mesh.faces.size(),
                                    cloth.front().size(), faces.size()));
    }
    cloth.push_back(std::move(mesh.vertices));
  }
  const int n = static_cast<int>(cloth.front().size());

  // The scene gives the body, the rest shape and the seam links; without it the page shows the
  // garment alone.
  std::unique_ptr<sim::Scene> scene;
  std::unique_ptr<sim::ClothModel> model;
  if (m.contains("scene_file") && m.at("scene_file").is_string()) {
    const fs::path sf = m.at("scene_file").get<std::string>();
    if (!fs::exists(sf)) {
      summary.notes.push_back(
          fmt::format("scene file {} not found: no body and no strain colouring", sf.string()));
    } else {
      try {
        scene = std::make_unique<sim::Scene>(sim::load_scene(sf));
      } catch (const InputError& e) {
        // A run viewed elsewhere (its data moved, CLOTHCD_DATA unset) still has its frames.
        summary.notes.push_back(
            fmt::format("cannot read the scene ({}): no body and no strain colouring", e.what()));
      }
      if (scene && static_cast<int>(scene->cloth.positions.size()) != n) {
        summary.notes.push_back(fmt::format(
            "scene file {} has a cloth of {} vertices, the frames {}: no strain colouring",
            sf.string(), scene->cloth.positions.size(), n));
      } else if (scene) {
        model = std::make_unique<sim::ClothModel>(scene->cloth, scene->material);
      }
    }
  }

  DataBlock block;
  nlohmann::json meshes = nlohmann::json::object();
  add_mesh(block, meshes, "cloth", faces, cloth);
  std::vector<std::vector<Vec3>> body;
  const std::vector<Face>* body_faces = nullptr;
  if (opt.body && scene && scene->body) {
    const double dt = m.at("frame_dt").get<double>();
    for (int f : frames) {
      body.emplace_back();
      scene->body->positions_at(f * dt, body.back());
    }
    body_faces = &scene->body->faces();
    add_mesh(block, meshes, "body", *body_faces, body);
    summary.body = true;
  }
  if (model) {
    std::vector<float> rest;
    std::vector<std::uint8_t> active;
    rest.reserve(faces.size() * 4);
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const auto& b = model->membrane_rest()[f].inv_rest;
      for (double x : {b(0, 0), b(0, 1), b(1, 0), b(1, 1)})
        rest.push_back(static_cast<float>(x));
      active.push_back(model->membrane_active()[f] ? 1 : 0);
    }
    block.add("rest", std::span<const float>(rest));
    block.add("membrane_active", std::span<const std::uint8_t>(active));
    summary.strain = true;
  }
  double h = opt.contact_distance;
  if (h <= 0.0) {
    const auto c = m.find("contact");
    h = c != m.end() && c->is_object() && c->contains("thickness") && c->at("thickness").is_number()
            ? c->at("thickness").get<double>()
            : 0.002;
  }
  if (opt.contact) {
    static const std::vector<std::pair<int, int>> no_links;
    const auto bits =
        contact_flags(faces, cloth, body_faces, body, h, model ? model->seam_links() : no_links);
    block.add("contact", std::span<const std::uint8_t>(bits));
    summary.contact = true;
  }

  nlohmann::json figures = nlohmann::json::array();
  for (int f : frames) {
    nlohmann::json e = frame_figures(m, f);
    e["frame"] = f;
    figures.push_back(std::move(e));
  }
  nlohmann::json meta = {{"kind", "sequence"},
                         {"title", fmt::format("clothcd view: {}", m.value("scene", "simulation"))},
                         {"run", run_summary(m)},
                         {"frames", figures},
                         {"meshes", meshes},
                         {"contact_distance", h},
                         {"strain", summary.strain},
                         {"contact", summary.contact},
                         {"notes", summary.notes}};
  summary.frames = static_cast<int>(frames.size());
  detail::write_page(out, std::move(meta), block, summary);
  return summary;
}

}  // namespace clothcd::view
