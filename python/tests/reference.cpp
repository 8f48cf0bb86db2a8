// The C++ side of the Python tests and of the binding speed comparison: runs SelfDetector through
// the C++ API and prints its results as JSON (doubles round-trip exactly).
//
//   clothcd_py_reference scene=NAME [n= seed= segments= rings= width=] [OPTIONS] [oracle=1]
//   clothcd_py_reference t0=FILE t1=FILE [OPTIONS] [runs=N]
// OPTIONS: policy= culling= bvh= thickness= threads=
// With runs=N, detect() is timed N times after one untimed call and only counts are printed.
#include <fmt/format.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/names.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"
#include "clothcd/research/oracle.hpp"
#include "clothcd/research/procedural.hpp"

namespace {

using namespace clothcd;
using Args = std::map<std::string, std::string>;

std::string get(const Args& a, const std::string& key, const std::string& fallback) {
  const auto it = a.find(key);
  return it == a.end() ? fallback : it->second;
}
int get_int(const Args& a, const std::string& key, int fallback) {
  return std::stoi(get(a, key, std::to_string(fallback)));
}

research::DetectOptions options(const Args& a) {
  research::DetectOptions o;
  research::set_cone_rule(o, research::parse_cone_rule(get(a, "policy", "proposed"), "policy"));
  research::set_culling_rule(o,
                             research::parse_culling_rule(get(a, "culling", "sound"), "culling"));
  o.build = parse_bvh_build(get(a, "bvh", "patch"), "bvh");
  o.thickness = std::stod(get(a, "thickness", "0"));
  return o;
}

research::ProceduralScene scene(const Args& a) {
  const std::string name = get(a, "scene", "");
  if (name == "stacked_sheets") return research::stacked_sheets(get_int(a, "n", 12));
  if (name == "winding_strip")
    return research::winding_strip(get_int(a, "segments", 96), get_int(a, "rings", 3));
  if (name == "crumpled_sheet")
    return research::crumpled_sheet(get_int(a, "n", 16), get_int(a, "seed", 1));
  if (name == "twisted_strip")
    return research::twisted_strip(get_int(a, "segments", 80), get_int(a, "width", 4));
  throw std::invalid_argument("unknown scene " + name);
}

nlohmann::json stats_json(const DetectStats& s) {
  return {{"box_tests", s.box_tests},
          {"nodes_culled", s.nodes_culled},
          {"cone_tests", s.cone_tests},
          {"contour_tests", s.contour_tests},
          {"contour_fails", s.contour_fails},
          {"internal_nodes", s.internal_nodes},
          {"triangle_pairs", s.triangle_pairs},
          {"vf_tests", s.vf_tests},
          {"ee_tests", s.ee_tests},
          {"vf_np_culled", s.vf_np_culled},
          {"ee_np_culled", s.ee_np_culled},
          {"vf_collisions", s.vf_collisions},
          {"ee_collisions", s.ee_collisions}};
}

nlohmann::json pairs_json(const DetectResult& r) {
  nlohmann::json vf = nlohmann::json::array(), ee = nlohmann::json::array();
  for (const auto& c : r.vf)
    vf.push_back({c.vertex, c.face, c.toi});
  for (const auto& c : r.ee)
    ee.push_back({c.edge_a, c.edge_b, c.toi});
  return {{"vf", vf}, {"ee", ee}, {"stats", stats_json(r.stats)}};
}

int run(const Args& a) {
  const research::DetectOptions o = options(a);
  const int threads = get_int(a, "threads", 0);
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  return arena.execute([&] {
    if (a.count("scene") != 0) {
      const research::ProceduralScene s = scene(a);
      research::SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      nlohmann::json j = pairs_json(det.detect(s.v_t0, s.v_t1));
      if (get(a, "oracle", "0") == "1") {
        const Topology topo(s.faces, s.num_vertices);
        clothcd::DetectOptions oo = o;
        oo.culling = Culling::None;
        j["oracle"] = pairs_json(research::brute_force_detect(topo, s.v_t0, s.v_t1, oo));
      }
      std::cout << j.dump() << '\n';
      return 0;
    }
    const TriangleMesh m0 = read_mesh(get(a, "t0", "")), m1 = read_mesh(get(a, "t1", ""));
    const Positions p0 = vertices_matrix(m0), p1 = vertices_matrix(m1);
    research::SelfDetector det(m0.faces, m0.num_vertices(), p0, o);
    const int runs = get_int(a, "runs", 0);
    if (runs <= 0) {
      std::cout << pairs_json(det.detect(p0, p1)).dump() << '\n';
      return 0;
    }
    DetectResult r = det.detect(p0, p1);  // untimed: first-touch allocations
    nlohmann::json seconds = nlohmann::json::array();
    for (int i = 0; i < runs; ++i) {
      const auto start = std::chrono::steady_clock::now();
      r = det.detect(p0, p1);
      seconds.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::cout
        << nlohmann::json{{"seconds", seconds}, {"vf", r.vf.size()}, {"ee", r.ee.size()}}.dump()
        << '\n';
    return 0;
  });
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    const auto eq = s.find('=');
    if (eq == std::string::npos) {
      std::cerr << "expected key=value, got " << s << '\n';
      return 2;
    }
    a[s.substr(0, eq)] = s.substr(eq + 1);
  }
  try {
    return run(a);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  }
}
