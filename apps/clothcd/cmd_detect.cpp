// `clothcd detect --t0 FILE --t1 FILE ...`: continuous self-collision detection over one step
// between two frames with the same topology; prints a summary and optionally writes JSON.
#include <fmt/format.h>
#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/sewing.hpp"
#include "command.hpp"

namespace {

namespace fs = std::filesystem;
using namespace clothcd;

struct Args {
  std::string t0, t1, json;
  std::string policy = "proposed", culling = "none", bvh = "spatial";
  double weld = 0, thickness = 0;
  int threads = 0;
  bool verify = false;
};

nlohmann::json stats_json(const DetectStats& s) {
  return {{"box_tests", s.box_tests},
          {"nodes_culled", s.nodes_culled},
          {"cone_tests", s.cone_tests},
          {"contour_tests", s.contour_tests},
          {"contour_fails", s.contour_fails},
          {"internal_nodes", s.internal_nodes},
          {"connected_internal_nodes", s.connected_internal_nodes},
          {"connected_share", s.connected_share()},
          {"disk_internal_nodes", s.disk_internal_nodes},
          {"adjacent_pairs", s.adjacent_pairs},
          {"triangle_pairs", s.triangle_pairs},
          {"vf_tests", s.vf_tests},
          {"ee_tests", s.ee_tests},
          {"vf_np_culled", s.vf_np_culled},
          {"ee_np_culled", s.ee_np_culled},
          {"vf_orphans", s.vf_orphans},
          {"ee_orphans", s.ee_orphans},
          {"vf_collisions", s.vf_collisions},
          {"ee_collisions", s.ee_collisions},
          {"time_refit", s.time_refit},
          {"time_traverse", s.time_traverse},
          {"time_narrow", s.time_narrow}};
}

void write_atomically(const fs::path& file, const nlohmann::json& j) {
  fs::path tmp = file;
  tmp += ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw input_error(tmp.string(), 0, "cannot write file");
    out << j.dump(1) << '\n';
    if (!out) throw input_error(tmp.string(), 0, "write failed");
  }
  fs::rename(tmp, file);
}

template <class T>
T pick(const std::string& name, const std::string& value, const std::map<std::string, T>& m) {
  const auto it = m.find(value);
  if (it == m.end()) throw InputError(fmt::format("--{}: unknown value '{}'", name, value));
  return it->second;
}

int run(const Args& a) {
  TriangleMesh m0 = read_mesh(a.t0);
  TriangleMesh m1 = read_mesh(a.t1);
  check_same_topology(m0, a.t0, m1, a.t1);
  DetectOptions o;
  o.policy = pick<ConePolicy>("policy", a.policy,
                              {{"provot", ConePolicy::Provot},
                               {"proposed", ConePolicy::Proposed},
                               {"exact", ConePolicy::Exact},
                               {"optimal", ConePolicy::Optimal}});
  o.culling = pick<Culling>("culling", a.culling,
                            {{"none", Culling::None},
                             {"cone", Culling::Cone},
                             {"gated", Culling::Gated},
                             {"sound", Culling::Sound}});
  o.build =
      pick<BvhBuild>("bvh", a.bvh, {{"spatial", BvhBuild::Spatial}, {"patch", BvhBuild::Patch}});
  if (!(a.thickness >= 0)) throw InputError("--thickness must be >= 0");
  o.thickness = a.thickness;
  o.verify = a.verify;

  // Original id of each detector vertex (the smallest original id of a welded cluster).
  std::vector<int> original(m0.num_vertices());
  for (int i = 0; i < m0.num_vertices(); ++i)
    original[i] = i;
  TriangleMesh w0 = m0, w1 = m1;
  if (a.weld > 0) {
    SewnMesh sewn = weld(m0, a.weld);
    w0 = sewn.mesh;
    original.assign(w0.num_vertices(), -1);
    for (int i = static_cast<int>(sewn.vertex_map.size()) - 1; i >= 0; --i) {
      original[sewn.vertex_map[i]] = i;
    }
    w1 = w0;
    for (int n = 0; n < w0.num_vertices(); ++n)
      w1.vertices[n] = m1.vertices[original[n]];
    fmt::print("welded {} vertices ({} -> {}), {} faces dropped, components {} -> {}\n",
               sewn.report.vertices_welded, m0.num_vertices(), w0.num_vertices(),
               sewn.report.faces_dropped, sewn.report.components_before,
               sewn.report.components_after);
  }
  std::optional<tbb::global_control> threads;
  if (a.threads > 0) {
    threads.emplace(tbb::global_control::max_allowed_parallelism,
                    static_cast<std::size_t>(a.threads));
  }
  SelfDetector det(w0.faces, w0.num_vertices(), vertices_matrix(w0), o);
  const DetectResult r = det.detect(vertices_matrix(w0), vertices_matrix(w1));
  const DetectStats& s = r.stats;
  fmt::print(
      "{} triangles, bvh {} ({:.1f}% edge-connected internal nodes), policy {}, culling {}\n"
      "triangle pairs {}, nodes culled {}, VF tests {} (NP culled {}), EE tests {} (NP culled "
      "{})\ncollisions: {} VF, {} EE\ntime: refit {:.4f} s, traversal {:.4f} s, narrow phase "
      "{:.4f} s\n",
      w0.num_faces(), a.bvh, 100 * s.connected_share(), a.policy, a.culling, s.triangle_pairs,
      s.nodes_culled, s.vf_tests, s.vf_np_culled, s.ee_tests, s.ee_np_culled, r.vf.size(),
      r.ee.size(), s.time_refit, s.time_traverse, s.time_narrow);
  if (r.verified) {
    fmt::print(
        "verify: {} VF and {} EE collisions missed against culling none ({} triangle "
        "pairs)\n",
        r.missed_vf.size(), r.missed_ee.size(), r.unculled_triangle_pairs);
  }
  if (!a.json.empty()) {
    auto vf_json = [&](const std::vector<VertexFaceCollision>& list) {
      nlohmann::json out = nlohmann::json::array();
      for (const auto& c : list) {
        out.push_back({{"vertex", original[c.vertex]},
                       {"face",
                        {original[c.face_vertices[0]], original[c.face_vertices[1]],
                         original[c.face_vertices[2]]}},
                       {"toi", c.toi}});
      }
      return out;
    };
    auto ee_json = [&](const std::vector<EdgeEdgeCollision>& list) {
      nlohmann::json out = nlohmann::json::array();
      for (const auto& c : list) {
        out.push_back({{"edge_a", {original[c.edge_a_vertices[0]], original[c.edge_a_vertices[1]]}},
                       {"edge_b", {original[c.edge_b_vertices[0]], original[c.edge_b_vertices[1]]}},
                       {"toi", c.toi}});
      }
      return out;
    };
    nlohmann::json j{{"vf", vf_json(r.vf)}, {"ee", ee_json(r.ee)}, {"stats", stats_json(s)}};
    if (r.verified) {
      j["missed_vf"] = vf_json(r.missed_vf);
      j["missed_ee"] = ee_json(r.missed_ee);
    }
    write_atomically(a.json, j);
  }
  return 0;
}

const bool registered = clothcd::app::register_command(
    "detect", "Continuous self-collision detection between two frames (OBJ or PLY)",
    [](CLI::App& sub) {
      auto a = std::make_shared<Args>();
      sub.add_option("--t0", a->t0, "frame at the start of the step")->required();
      sub.add_option("--t1", a->t1, "frame at the end of the step (same topology)")->required();
      sub.add_option("--policy", a->policy, "cone policy: provot|proposed|exact|optimal");
      sub.add_option("--culling", a->culling, "culling: none|cone|gated|sound");
      sub.add_option("--bvh", a->bvh, "BVH build: spatial|patch");
      sub.add_option("--weld", a->weld, "weld vertices closer than this first (0: off)");
      sub.add_option("--thickness", a->thickness, "contact distance (>= 0)");
      sub.add_option("--threads", a->threads, "worker threads (0: all)");
      sub.add_flag("--verify", a->verify, "also run culling none and report missed collisions");
      sub.add_option("--json", a->json, "write collisions and statistics to this JSON file");
      return [a] { return run(*a); };
    });

}  // namespace
