// `clothcd detect --t0 FILE --t1 FILE ...`: continuous self-collision detection over one step
// between two frames with the same topology (or t0 and a smooth perturbation of it); prints a
// summary and optionally writes JSON, or a table of every build, culling mode and policy.
#include <fmt/format.h>
#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "atomic_json.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/names.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/sewing.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"
#include "clothcd/research/procedural.hpp"
#include "command.hpp"
#include "misses.hpp"

// A namespace of its own: the commands are compiled together (unity build).
namespace {
namespace detect_command {

namespace fs = std::filesystem;
using namespace clothcd;
// The research detector: the CLI offers the unsound rules, the optimal cones and --verify.
using research::DetectOptions;
using research::DetectResult;
using research::SelfDetector;

struct Args {
  std::string t0, t1, json;
  std::string policy = "proposed", culling = "none", bvh = "spatial";
  double weld = 0, sew = 0, thickness = 0;
  double toi_tolerance = -1;  // unset: each mode's default
  double first_window = 0;
  double perturb = 0, wavelength = 0.2;
  std::uint64_t seed = 1;
  int garment_vertices = -1;
  int threads = 0;
  int cull_min_triangles = 0;
  bool verify = false, table = false, table_optimal = false, no_distance_filter = false;
  bool earliest = false;
  int repeat = 0;
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
          {"triangle_pairs_apart", s.triangle_pairs_apart},
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

// A time of impact as JSON: the shortest text that reads back to the same double, always with a
// fraction or exponent so that readers see a float (as nlohmann::json writes 0.0 and 1.0).
void append_toi(fmt::memory_buffer& b, double t) {
  const auto start = b.size();
  fmt::format_to(std::back_inserter(b), "{}", t);
  const std::string_view text(b.data() + start, b.size() - start);
  if (text.find_first_of(".e") == std::string_view::npos)
    fmt::format_to(std::back_inserter(b), ".0");
}

// The collisions and statistics of a step as JSON (keys in the order nlohmann::json sorts them),
// one collision per line. Written directly: a document of 100 K collisions built as
// nlohmann::json objects took longer than the detection's narrow phase.
void write_result_json(std::ostream& out, const DetectResult& r, const nlohmann::json& stats,
                       const std::vector<int>& original) {
  fmt::memory_buffer b;
  auto vf = [&](const char* key, const std::vector<VertexFaceCollision>& list, bool last) {
    fmt::format_to(std::back_inserter(b), " \"{}\": [", key);
    for (std::size_t i = 0; i < list.size(); ++i) {
      const VertexFaceCollision& c = list[i];
      fmt::format_to(
          std::back_inserter(b), "{}\n  {{\"face\": [{}, {}, {}], \"toi\": ", i == 0 ? "" : ",",
          original[c.face_vertices[0]], original[c.face_vertices[1]], original[c.face_vertices[2]]);
      append_toi(b, c.toi);
      fmt::format_to(std::back_inserter(b), ", \"vertex\": {}}}", original[c.vertex]);
    }
    fmt::format_to(std::back_inserter(b), "{}]{}\n", list.empty() ? "" : "\n ", last ? "" : ",");
  };
  auto ee = [&](const char* key, const std::vector<EdgeEdgeCollision>& list) {
    fmt::format_to(std::back_inserter(b), " \"{}\": [", key);
    for (std::size_t i = 0; i < list.size(); ++i) {
      const EdgeEdgeCollision& c = list[i];
      fmt::format_to(
          std::back_inserter(b),
          "{}\n  {{\"edge_a\": [{}, {}], \"edge_b\": [{}, {}], \"toi\": ", i == 0 ? "" : ",",
          original[c.edge_a_vertices[0]], original[c.edge_a_vertices[1]],
          original[c.edge_b_vertices[0]], original[c.edge_b_vertices[1]]);
      append_toi(b, c.toi);
      fmt::format_to(std::back_inserter(b), "}}");
    }
    fmt::format_to(std::back_inserter(b), "{}],\n", list.empty() ? "" : "\n ");
  };
  const research::Verification& ver = r.verification;
  fmt::format_to(std::back_inserter(b), "{{\n");
  ee("ee", r.ee);
  if (ver.ran) {
    ee("missed_ee", ver.missed_ee);
    vf("missed_vf", ver.missed_vf, false);
  }
  std::string st = stats.dump(1);
  for (std::size_t k = st.find('\n'); k != std::string::npos; k = st.find('\n', k + 2))
    st.insert(k + 1, " ");
  fmt::format_to(std::back_inserter(b), " \"stats\": {},\n", st);
  vf("vf", r.vf, true);
  fmt::format_to(std::back_inserter(b), "}}\n");
  out.write(b.data(), static_cast<std::streamsize>(b.size()));
}

// The two frames of the step: --t1, or t0 plus a smooth perturbation; optionally cut to the
// garment prefix of a drape.obj (its first N vertices and the faces that use only them).
std::pair<TriangleMesh, TriangleMesh> load_frames(const Args& a) {
  if (a.t1.empty() == (a.perturb <= 0)) {
    throw InputError("give exactly one of --t1 FILE and --perturb AMPLITUDE (> 0)");
  }
  TriangleMesh m0 = read_mesh(a.t0);
  TriangleMesh m1;
  if (!a.t1.empty()) {
    m1 = read_mesh(a.t1);
    check_same_topology(m0, a.t0, m1, a.t1);
  }
  if (a.garment_vertices >= 0) {
    int nf = 0;
    while (nf < m0.num_faces()) {
      const Face& t = m0.faces[nf];
      if (std::max({t[0], t[1], t[2]}) >= a.garment_vertices) break;
      ++nf;
    }
    m0 = submesh_prefix(m0, a.garment_vertices, nf);
    if (!a.t1.empty()) m1 = submesh_prefix(m1, a.garment_vertices, nf);
    fmt::print("garment prefix: {} vertices, {} faces\n", m0.num_vertices(), m0.num_faces());
  }
  if (a.perturb > 0) {
    m1 = m0;
    const Positions p =
        research::smooth_perturbation(vertices_matrix(m0), a.perturb, a.wavelength, a.seed);
    for (int i = 0; i < m1.num_vertices(); ++i)
      m1.vertices[i] = p.row(i).transpose();
    fmt::print("t1 = t0 + smooth perturbation (amplitude {}, wavelength {}, seed {})\n", a.perturb,
               a.wavelength, a.seed);
  }
  return {std::move(m0), std::move(m1)};
}

// One row of --table: a configuration and its result.
struct Row {
  std::string_view bvh, culling, policy;
  DetectResult r;
};

using cli::missed_against;

// Every build x culling mode x policy on one step, as a markdown table (misses and culled pairs
// against `none` of the same build).
void print_table(const TriangleMesh& w0, const TriangleMesh& w1, double thickness,
                 bool with_optimal, bool distance_filter) {
  const Positions p0 = vertices_matrix(w0), p1 = vertices_matrix(w1);
  const BvhBuild builds[] = {BvhBuild::Spatial, BvhBuild::Patch};
  using research::ConeRule;
  using research::CullingRule;
  const CullingRule modes[] = {CullingRule::Cone, CullingRule::Gated, CullingRule::Sound};
  const ConeRule policies[] = {ConeRule::Provot, ConeRule::Proposed, ConeRule::Exact,
                               ConeRule::Optimal};
  fmt::print(
      "\n| bvh | culling | policy | connected / disk internal nodes | triangle pairs | pairs "
      "culled "
      "vs none | nodes culled | contour fails | VF / EE tests | collisions | missed vs none | "
      "refit / traverse / narrow (s) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const BvhBuild build : builds) {
    DetectOptions o;
    o.build = build;
    o.thickness = thickness;
    o.distance_filter = distance_filter;
    SelfDetector det(w0.faces, w0.num_vertices(), p0, o);
    const DetectResult none = det.detect(p0, p1);
    std::vector<Row> rows;
    rows.push_back({to_string(build), to_string(Culling::None), "-", none});
    for (const CullingRule mode : modes) {
      for (const ConeRule policy : policies) {
        if (policy == ConeRule::Optimal && !with_optimal) continue;
        research::set_culling_rule(o, mode);
        research::set_cone_rule(o, policy);
        det.set_options(o);
        rows.push_back({to_string(build), research::to_string(mode), research::to_string(policy),
                        det.detect(p0, p1)});
      }
    }
    for (const Row& row : rows) {
      const DetectStats& s = row.r.stats;
      const double culled = 100.0 * (double(none.stats.triangle_pairs) - double(s.triangle_pairs)) /
                            std::max<double>(1.0, double(none.stats.triangle_pairs));
      fmt::print(
          "| {} | {} | {} | {:.2f}% / {:.2f}% | {} | {:.2f}% | {} | {} | {} / {} | {} | {} | "
          "{:.3f} / {:.3f} / {:.3f} |\n",
          row.bvh, row.culling, row.policy, 100 * s.connected_share(),
          100.0 * s.disk_internal_nodes / std::max(1, s.internal_nodes), s.triangle_pairs, culled,
          s.nodes_culled, s.contour_fails, s.vf_tests, s.ee_tests,
          row.r.vf.size() + row.r.ee.size(), missed_against(none, row.r), s.time_refit,
          s.time_traverse, s.time_narrow);
    }
  }
}

// --earliest: the earliest time of impact of the step and its pair, printed and as JSON.
void run_earliest(const Args& a, SelfDetector& det, const TriangleMesh& w0, const TriangleMesh& w1,
                  const std::vector<int>& original) {
  EarliestOptions eo;
  if (a.toi_tolerance >= 0) eo.toi_tolerance = a.toi_tolerance;
  eo.first_window = a.first_window;
  const Eigen::MatrixX3d x0 = vertices_matrix(w0), x1 = vertices_matrix(w1);
  const EarliestImpact e = det.earliest_impact(x0, x1, eo);
  const DetectStats& s = e.stats;
  // --repeat: the query again on the same detector, as a line search calls it; each timed call
  // follows one on three quarters of the step (a shorter step, as a line search tries), so that
  // every moving vertex changed between timed calls.
  std::vector<std::array<double, 3>> warm;
  if (a.repeat > 0) {
    const Eigen::MatrixX3d other = x0 + 0.75 * (x1 - x0);
    for (int k = 0; k < a.repeat; ++k) {
      (void)det.earliest_impact(x0, other, eo);
      const EarliestImpact r = det.earliest_impact(x0, x1, eo);
      if (r.toi != e.toi || r.kind != e.kind || r.ids != e.ids) {
        throw std::logic_error("--repeat: a repeated query gave another answer");
      }
      warm.push_back({r.stats.time_refit, r.stats.time_traverse, r.stats.time_narrow});
    }
  }
  const Topology& topo = det.topology();
  // The pair as vertex ids of the input files (as --json writes collisions).
  nlohmann::json ids = nlohmann::json::array();
  std::string kind = "none", what = "nothing comes within the thickness";
  if (e.kind == EarliestImpact::Kind::VertexFace) {
    const Face& f = topo.faces()[e.ids[1]];
    kind = "vf";
    ids = {original[e.ids[0]], {original[f[0]], original[f[1]], original[f[2]]}};
    what = fmt::format("vertex {} and face ({}, {}, {})", original[e.ids[0]], original[f[0]],
                       original[f[1]], original[f[2]]);
  } else if (e.kind == EarliestImpact::Kind::EdgeEdge) {
    const Edge& p = topo.edges()[e.ids[0]];
    const Edge& q = topo.edges()[e.ids[1]];
    kind = "ee";
    ids = {{original[p[0]], original[p[1]]}, {original[q[0]], original[q[1]]}};
    what = fmt::format("edges ({}, {}) and ({}, {})", original[p[0]], original[p[1]],
                       original[q[0]], original[q[1]]);
  }
  fmt::print(
      "earliest impact: toi {} ({}), {} time window(s) from [0, {}]\ntriangle pairs {}, VF tests "
      "{}, EE tests "
      "{}\ntime: refit {:.4f} s, traversal {:.4f} s, narrow phase {:.4f} s\n",
      e.toi, what, e.windows, e.first_window, s.triangle_pairs, s.vf_tests, s.ee_tests,
      s.time_refit, s.time_traverse, s.time_narrow);
  if (!a.json.empty()) {
    nlohmann::json j;
    nlohmann::json stats = stats_json(s);
    stats["windows"] = e.windows;
    stats["first_window"] = e.first_window;
    j["earliest"] = {{"toi", e.toi}, {"kind", kind}, {"ids", ids}};
    j["stats"] = stats;
    if (!warm.empty()) {
      nlohmann::json calls = nlohmann::json::array();
      for (const auto& w : warm)
        calls.push_back({{"time_refit", w[0]}, {"time_traverse", w[1]}, {"time_narrow", w[2]}});
      j["repeat"] = calls;
    }
    clothcd::io_detail::write_atomically(a.json,
                                         [&](std::ostream& out) { out << j.dump(1) << "\n"; });
  }
}

int run(const Args& a) {
  DetectOptions o;
  research::set_cone_rule(o, research::parse_cone_rule(a.policy, "--policy"));
  research::set_culling_rule(o, research::parse_culling_rule(a.culling, "--culling"));
  o.build = parse_bvh_build(a.bvh, "--bvh");
  if (!(a.thickness >= 0)) throw InputError("--thickness must be >= 0");
  if (a.cull_min_triangles < 0) throw InputError("--cull-min-triangles must be >= 0");
  if (a.weld > 0 && a.sew > 0) throw InputError("give at most one of --weld and --sew");
  if (a.table && !a.json.empty()) throw InputError("--table writes no JSON; drop --json");
  o.thickness = a.thickness;
  o.cull_min_triangles = a.cull_min_triangles;
  o.distance_filter = !a.no_distance_filter;
  o.research.verify = a.verify;
  if (a.toi_tolerance >= 0 && !a.earliest) o.toi_tolerance = a.toi_tolerance;
  if (a.earliest && (a.table || a.verify)) {
    throw InputError("--earliest reports one pair; drop --table and --verify");
  }
  if (a.first_window != 0 && !a.earliest) throw InputError("--first-window needs --earliest");
  if (a.repeat != 0 && !a.earliest) throw InputError("--repeat needs --earliest");
  const auto start = std::chrono::steady_clock::now();
  const auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  const auto [m0, m1] = load_frames(a);

  // Original id of each detector vertex (the smallest original id of a welded cluster).
  std::vector<int> original(m0.num_vertices());
  for (int i = 0; i < m0.num_vertices(); ++i)
    original[i] = i;
  TriangleMesh w0 = m0, w1 = m1;
  if (a.weld > 0 || a.sew > 0) {
    // Sewing also splits T-junction edges at existing vertices, so the vertex map stays valid.
    SewnMesh sewn = a.sew > 0 ? sew(m0, a.sew) : weld(m0, a.weld);
    w0 = sewn.mesh;
    original.assign(w0.num_vertices(), -1);
    for (int i = static_cast<int>(sewn.vertex_map.size()) - 1; i >= 0; --i) {
      original[sewn.vertex_map[i]] = i;
    }
    w1 = w0;
    for (int n = 0; n < w0.num_vertices(); ++n)
      w1.vertices[n] = m1.vertices[original[n]];
    const SewingReport& rep = sewn.report;
    fmt::print(
        "{} {} vertices ({} -> {}), {} edges split, {} faces dropped, components {} -> {}, "
        "non-manifold edges {} -> {}\n",
        a.sew > 0 ? "sewn: welded" : "welded", rep.vertices_welded, m0.num_vertices(),
        w0.num_vertices(), rep.edges_split, rep.faces_dropped, rep.components_before,
        rep.components_after, rep.nonmanifold_edges_before, rep.nonmanifold_edges_after);
  }
  std::optional<tbb::global_control> threads;
  if (a.threads > 0) {
    threads.emplace(tbb::global_control::max_allowed_parallelism,
                    static_cast<std::size_t>(a.threads));
  }
  if (a.table) {
    print_table(w0, w1, a.thickness, a.table_optimal, !a.no_distance_filter);
    return 0;
  }
  const double reading = since(start);
  const auto built = std::chrono::steady_clock::now();
  SelfDetector det(w0.faces, w0.num_vertices(), vertices_matrix(w0), o);
  const double setup = since(built);
  if (a.earliest) {
    run_earliest(a, det, w0, w1, original);
    fmt::print("setup: reading {:.4f} s, detector {:.4f} s\n", reading, setup);
    return 0;
  }
  const DetectResult r = det.detect(vertices_matrix(w0), vertices_matrix(w1));
  const DetectStats& s = r.stats;
  fmt::print(
      "{} triangles, bvh {} ({:.1f}% edge-connected, {:.1f}% disk internal nodes), policy {}, "
      "culling {}\ntriangle pairs {} ({} culled whole by the triangle distance bound), nodes "
      "culled {}, VF "
      "tests {} (NP culled {}), EE tests {} (NP culled {})\ncollisions: {} VF, {} EE\ntime: refit "
      "{:.4f} s, traversal {:.4f} s, narrow phase {:.4f} s\nsetup: reading {:.4f} s, detector "
      "{:.4f} s (topology, tree, orphans, ownership)\n",
      w0.num_faces(), a.bvh, 100 * s.connected_share(),
      100.0 * s.disk_internal_nodes / std::max(1, s.internal_nodes), a.policy, a.culling,
      s.triangle_pairs, s.triangle_pairs_apart, s.nodes_culled, s.vf_tests, s.vf_np_culled,
      s.ee_tests, s.ee_np_culled, r.vf.size(), r.ee.size(), s.time_refit, s.time_traverse,
      s.time_narrow, reading, setup);
  const research::Verification& ver = r.verification;
  if (ver.ran) {
    fmt::print(
        "verify: {} VF and {} EE collisions missed against culling none ({} triangle "
        "pairs)\n",
        ver.missed_vf.size(), ver.missed_ee.size(), ver.unculled_triangle_pairs);
  }
  if (!a.json.empty()) {
    clothcd::io_detail::write_atomically(
        a.json, [&](std::ostream& out) { write_result_json(out, r, stats_json(s), original); });
  }
  return 0;
}

const bool registered = clothcd::app::register_command(
    "detect", "Continuous self-collision detection between two frames (OBJ or PLY)",
    [](CLI::App& sub) {
      auto a = std::make_shared<Args>();
      sub.add_option("--t0", a->t0, "frame at the start of the step")->required();
      sub.add_option("--t1", a->t1, "frame at the end of the step (same topology)");
      sub.add_option("--perturb", a->perturb,
                     "instead of --t1: step to t0 plus a smooth perturbation of this amplitude");
      sub.add_option("--wavelength", a->wavelength, "wavelength of the perturbation (0.2)");
      sub.add_option("--seed", a->seed, "seed of the perturbation (1)");
      sub.add_option("--garment-vertices", a->garment_vertices,
                     "keep the first N vertices and the faces using only them (a drape.obj "
                     "garment)");
      sub.add_option("--policy", a->policy, "cone policy: provot|proposed|exact|optimal");
      sub.add_option("--culling", a->culling, "culling: none|cone|gated|sound");
      sub.add_option("--bvh", a->bvh, "BVH build: spatial|patch");
      sub.add_option("--weld", a->weld, "weld vertices closer than this first (0: off)");
      sub.add_option("--sew", a->sew, "weld and conform T-junctions at this tolerance (0: off)");
      sub.add_option("--thickness", a->thickness, "contact distance (>= 0)");
      sub.add_option("--cull-min-triangles", a->cull_min_triangles,
                     "sound culling tests only nodes of at least this many triangles (0: all; "
                     "same results, less work)");
      sub.add_option("--threads", a->threads, "worker threads (0: all)");
      sub.add_flag("--no-distance-filter", a->no_distance_filter,
                   "at zero thickness, skip the distance filter: test every triangle pair's "
                   "feature pairs with the NP filter and the kernels (the paper's narrow phase) "
                   "instead of first dropping the triangle and feature pairs that provably stay "
                   "apart");
      sub.add_flag("--verify", a->verify, "also run culling none and report missed collisions");
      sub.add_flag("--table", a->table,
                   "print a table of every BVH build, culling mode and cone policy instead");
      sub.add_flag("--table-optimal", a->table_optimal, "include the OPTIMAL policy in --table");
      sub.add_option("--json", a->json, "write collisions and statistics to this JSON file");
      sub.add_flag("--earliest", a->earliest,
                   "report only the earliest time of impact and its pair (the collision-free "
                   "step of a line search) instead of every collision");
      sub.add_option("--toi-tolerance", a->toi_tolerance,
                     "how far early a time of impact may be (default 1e-4; with --earliest 1e-6)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--repeat", a->repeat,
                     "with --earliest: N more queries on the same detector, each after one on "
                     "3/4 of the step (a line search's calls); their times go to the JSON's "
                     "\"repeat\" list")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--first-window", a->first_window,
                     "with --earliest: the first time window [0, T], T a power of two in (0, 1] "
                     "(default: from the motion)");
      return [a] { return run(*a); };
    });

}  // namespace detect_command
}  // namespace
