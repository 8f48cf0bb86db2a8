// SelfDetector, PairDetector, their results and the procedural test scenes.
#include <fmt/format.h>

#include <optional>

#include "arrays.hpp"
#include "bindings.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/names.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd::python {
namespace {

// The research detector and options: the Python module offers the unsound rules, the optimal
// cones and verify.
using research::DetectOptions;
using research::DetectResult;
using research::SelfDetector;

// The options shared by both detectors' constructors; all keyword-only in Python.
struct OptionArgs {
  std::optional<std::string> policy, culling;
  std::optional<double> thickness, toi_tolerance, reuse_distance;
  std::optional<bool> np_filter, fast_path;
  std::optional<int> distance_filter_depth;
  std::optional<int> cull_min_triangles;
  std::optional<bool> reuse_front;
  std::optional<bool> distance_filter;

  void apply(DetectOptions& o) const {
    // Research names included ("cone", "gated", "optimal"): they set the research options.
    if (policy) research::set_cone_rule(o, research::parse_cone_rule(*policy, "policy"));
    if (culling) research::set_culling_rule(o, research::parse_culling_rule(*culling, "culling"));
    if (thickness) {
      if (!(*thickness >= 0) || !std::isfinite(*thickness)) {
        fail(fmt::format("thickness must be finite and >= 0, got {}", *thickness));
      }
      o.thickness = *thickness;
    }
    if (toi_tolerance) o.toi_tolerance = *toi_tolerance;
    if (reuse_distance) o.reuse_distance = *reuse_distance;
    if (np_filter) o.np_filter = *np_filter;
    if (fast_path) o.fast_path = *fast_path;
    if (distance_filter_depth) o.distance_filter_depth = *distance_filter_depth;
    if (cull_min_triangles) {
      if (*cull_min_triangles < 0) {
        fail(fmt::format("cull_min_triangles must be >= 0, got {}", *cull_min_triangles));
      }
      o.cull_min_triangles = *cull_min_triangles;
    }
    if (reuse_front) o.reuse_front = *reuse_front;
    if (distance_filter) o.distance_filter = *distance_filter;
  }
};

py::dict options_dict(const DetectOptions& o, const char* bvh) {
  py::dict d;
  d["policy"] = std::string(research::to_string(research::cone_rule(o)));
  d["culling"] = std::string(research::to_string(research::culling_rule(o)));
  d["bvh"] = bvh;
  d["thickness"] = o.thickness;
  d["np_filter"] = o.np_filter;
  d["distance_filter"] = o.distance_filter;
  d["fast_path"] = o.fast_path;
  d["toi_tolerance"] = o.toi_tolerance;
  d["distance_filter_depth"] = o.distance_filter_depth;
  d["reuse_distance"] = o.reuse_distance;
  d["cull_min_triangles"] = o.cull_min_triangles;
  d["reuse_front"] = o.reuse_front;
  return d;
}

py::dict stats_dict(const DetectStats& s) {
  py::dict d;
  d["box_tests"] = s.box_tests;
  d["nodes_culled"] = s.nodes_culled;
  d["cone_tests"] = s.cone_tests;
  d["contour_tests"] = s.contour_tests;
  d["contour_fails"] = s.contour_fails;
  d["front_pairs"] = s.front_pairs;
  d["internal_nodes"] = s.internal_nodes;
  d["connected_internal_nodes"] = s.connected_internal_nodes;
  d["connected_share"] = s.connected_share();
  d["disk_internal_nodes"] = s.disk_internal_nodes;
  d["adjacent_pairs"] = s.adjacent_pairs;
  d["triangle_pairs"] = s.triangle_pairs;
  d["triangle_pairs_apart"] = s.triangle_pairs_apart;
  d["vf_tests"] = s.vf_tests;
  d["ee_tests"] = s.ee_tests;
  d["vf_np_culled"] = s.vf_np_culled;
  d["ee_np_culled"] = s.ee_np_culled;
  d["vf_orphans"] = s.vf_orphans;
  d["ee_orphans"] = s.ee_orphans;
  d["vf_collisions"] = s.vf_collisions;
  d["ee_collisions"] = s.ee_collisions;
  d["time_refit"] = s.time_refit;
  d["time_traverse"] = s.time_traverse;
  d["time_narrow"] = s.time_narrow;
  return d;
}

// (k, 2) ids and (k,) values of a list of records.
template <class T, class Ids, class Value>
std::pair<py::array_t<int>, py::array_t<double>> columns(const std::vector<T>& list, Ids ids,
                                                         Value value) {
  const auto k = static_cast<py::ssize_t>(list.size());
  py::array_t<int> pairs({k, py::ssize_t{2}});
  py::array_t<double> values(k);
  int* p = pairs.mutable_data();
  double* t = values.mutable_data();
  for (py::ssize_t i = 0; i < k; ++i) {
    const auto [a, b] = ids(list[i]);
    p[2 * i] = a;
    p[2 * i + 1] = b;
    t[i] = value(list[i]);
  }
  return {pairs, values};
}

template <class T>
std::pair<py::array_t<int>, py::array_t<double>> vf_columns(const std::vector<T>& list) {
  return columns(
      list,
      [](const T& c) {
        return std::pair{c.vertex, c.face};
      },
      [](const T& c) { return c.toi; });
}
std::pair<py::array_t<int>, py::array_t<double>> ee_columns(
    const std::vector<EdgeEdgeCollision>& list) {
  return columns(
      list,
      [](const EdgeEdgeCollision& c) {
        return std::pair{c.edge_a, c.edge_b};
      },
      [](const EdgeEdgeCollision& c) { return c.toi; });
}

struct SelfResult {
  py::array_t<int> vf, ee;
  py::array_t<double> vf_toi, ee_toi;
  py::dict stats;
  std::optional<py::array_t<int>> missed_vf, missed_ee;

  explicit SelfResult(const DetectResult& r) : stats(stats_dict(r.stats)) {
    std::tie(vf, vf_toi) = vf_columns(r.vf);
    std::tie(ee, ee_toi) = ee_columns(r.ee);
    const research::Verification& ver = r.verification;
    if (ver.ran) {
      missed_vf = vf_columns(ver.missed_vf).first;
      missed_ee = ee_columns(ver.missed_ee).first;
      stats["unculled_triangle_pairs"] = ver.unculled_triangle_pairs;
    }
  }
};

struct ProximityOut {
  py::array_t<int> vf, ee;
  py::array_t<double> vf_distance, ee_distance;
  std::size_t reused_pairs = 0;

  explicit ProximityOut(const ProximityResult& r) : reused_pairs(r.reused_pairs) {
    std::tie(vf, vf_distance) = columns(
        r.vf,
        [](const auto& c) {
          return std::pair{c.vertex, c.face};
        },
        [](const auto& c) { return c.distance; });
    std::tie(ee, ee_distance) = columns(
        r.ee,
        [](const auto& c) {
          return std::pair{c.edge_a, c.edge_b};
        },
        [](const auto& c) { return c.distance; });
  }
};

struct PairResult {
  py::array_t<int> vf_a_on_b, vf_b_on_a, ee;
  py::array_t<double> vf_a_on_b_toi, vf_b_on_a_toi, ee_toi;
  py::dict stats;

  explicit PairResult(const PairDetectResult& r) : stats(stats_dict(r.stats)) {
    std::tie(vf_a_on_b, vf_a_on_b_toi) = vf_columns(r.vf_a_on_b);
    std::tie(vf_b_on_a, vf_b_on_a_toi) = vf_columns(r.vf_b_on_a);
    std::tie(ee, ee_toi) = ee_columns(r.ee);
  }
};

// EarliestImpact as Python's (toi, kind, ids): kind "vf" | "ee" | "none" for one mesh; between
// two meshes "vf_a_on_b" | "vf_b_on_a" | "ee" | "none".
py::tuple earliest_tuple(const EarliestImpact& e, bool two_meshes) {
  std::string kind = "none";
  if (e.kind == EarliestImpact::Kind::VertexFace) {
    kind = !two_meshes ? "vf" : e.vertex_on_b ? "vf_b_on_a" : "vf_a_on_b";
  } else if (e.kind == EarliestImpact::Kind::EdgeEdge) {
    kind = "ee";
  }
  return py::make_tuple(e.toi, kind, py::make_tuple(e.ids[0], e.ids[1]));
}

EarliestOptions earliest_options(double toi_tolerance, double first_window) {
  EarliestOptions o;
  o.toi_tolerance = toi_tolerance;
  o.first_window = first_window;
  return o;
}

// The Python SelfDetector: the library's, its worker arena and the arrays it was built from.
class PySelfDetector {
 public:
  PySelfDetector(const ArrayLike& F, const ArrayLike& V, const std::string& bvh,
                 const OptionArgs& args, int threads, const ArrayLike& linked)
      : workers_(threads), bvh_(bvh) {
    std::vector<Face> f = faces(F, "F");
    const Positions v = positions(V, "V_rest");
    DetectOptions o;
    o.build = parse_bvh_build(bvh, "bvh");
    o.culling = Culling::Sound;
    args.apply(o);
    if (!linked.obj.is_none()) o.linked_vertices = index_pairs(linked, "linked_vertices");
    det_.emplace(
        workers_.run([&] { return SelfDetector(std::move(f), static_cast<int>(v.rows()), v, o); }));
    // Linked ids are checked at the first detect(); check them now, at the call that gave them.
    if (!o.linked_vertices.empty()) {
      const int n = det_->topology().num_vertices();
      for (const auto& [a, b] : o.linked_vertices) {
        if (a < 0 || a >= n || b < 0 || b >= n) {
          fail(fmt::format("linked_vertices: pair ({}, {}) is out of range [0, {})", a, b, n));
        }
      }
    }
  }

  SelfResult detect(const ArrayLike& V0, const ArrayLike& V1) {
    const PointsArg a(V0, "V0"), b(V1, "V1");
    DetectResult r = workers_.run([&] {
      return with_points([&](const auto& x0, const auto& x1) { return det_->detect(x0, x1); }, a,
                         b);
    });
    return SelfResult(r);
  }

  py::tuple earliest_impact(const ArrayLike& V0, const ArrayLike& V1, double toi_tolerance,
                            double first_window) {
    const PointsArg a(V0, "V0"), b(V1, "V1");
    const EarliestOptions eo = earliest_options(toi_tolerance, first_window);
    const EarliestImpact e = workers_.run([&] {
      return with_points(
          [&](const auto& x0, const auto& x1) { return det_->earliest_impact(x0, x1, eo); }, a, b);
    });
    return earliest_tuple(e, false);
  }

  ProximityOut proximity(const ArrayLike& V, double h) {
    const PointsArg a(V, "V");
    ProximityResult r = workers_.run(
        [&] { return with_points([&](const auto& x) { return det_->proximity(x, h); }, a); });
    return ProximityOut(r);
  }

  void set_active_vertices(const ArrayLike& ids) {
    const std::vector<int> v = indices(ids, "ids");
    workers_.run([&] { det_->set_active_vertices(v); });
  }
  void set_active_faces(const ArrayLike& ids) {
    const std::vector<int> f = indices(ids, "ids");
    workers_.run([&] { det_->set_active_faces(f); });
  }
  void clear_active() {
    workers_.run([&] { det_->clear_active(); });
  }
  void rebuild(const ArrayLike& V) {
    const PointsArg a(V, "V");
    workers_.run([&] { with_points([&](const auto& x) { det_->rebuild(x); }, a); });
  }
  void set_options(const OptionArgs& args, std::optional<bool> verify) {
    DetectOptions o = det_->options();
    args.apply(o);
    if (verify) o.research.verify = *verify;
    workers_.run([&] { det_->set_options(o); });
  }

  [[nodiscard]] py::array_t<int> edges() const { return edges_array(det_->topology().edges()); }
  [[nodiscard]] py::array_t<int> faces_out() const {
    auto f = det_->topology().faces();
    return faces_array(std::move(f));
  }
  [[nodiscard]] int num_vertices() const { return det_->topology().num_vertices(); }
  [[nodiscard]] py::dict options() const {
    py::dict d = options_dict(det_->options(), bvh_.c_str());
    d["threads"] = workers_.threads();
    d["verify"] = det_->options().research.verify;
    return d;
  }

 private:
  Workers workers_;
  std::string bvh_;
  std::optional<SelfDetector> det_;
};

class PyPairDetector {
 public:
  PyPairDetector(const ArrayLike& Fa, const ArrayLike& Va, const ArrayLike& Fb, const ArrayLike& Vb,
                 const std::string& bvh, const OptionArgs& args, int threads)
      : workers_(threads) {
    std::vector<Face> fa = faces(Fa, "F_a"), fb = faces(Fb, "F_b");
    const Positions a = positions(Va, "V_a"), b = positions(Vb, "V_b");
    DetectOptions o;
    o.build = parse_bvh_build(bvh, "bvh");
    args.apply(o);
    if (!(o.research == research::Options{})) {
      fail(
          "PairDetector: the research culling rules and cones serve self-collision culling only; "
          "use culling 'none' and a policy between two meshes");
    }
    // The detector numbers edges as a Topology of the same faces does.
    const Topology ta(fa, static_cast<int>(a.rows())), tb(fb, static_cast<int>(b.rows()));
    edges_a_ = ta.edges();
    edges_b_ = tb.edges();
    det_.emplace(workers_.run([&] {
      return PairDetector(std::move(fa), static_cast<int>(a.rows()), a, std::move(fb),
                          static_cast<int>(b.rows()), b, o);
    }));
  }

  PairResult detect(const ArrayLike& A0, const ArrayLike& A1, const ArrayLike& B0,
                    const ArrayLike& B1) {
    const PointsArg a0(A0, "Va0"), a1(A1, "Va1"), b0(B0, "Vb0"), b1(B1, "Vb1");
    PairDetectResult r = workers_.run([&] {
      return with_points([&](const auto&... x) { return det_->detect(x...); }, a0, a1, b0, b1);
    });
    return PairResult(r);
  }

  py::tuple earliest_impact(const ArrayLike& A0, const ArrayLike& A1, const ArrayLike& B0,
                            const ArrayLike& B1, double toi_tolerance, double first_window) {
    const PointsArg a0(A0, "Va0"), a1(A1, "Va1"), b0(B0, "Vb0"), b1(B1, "Vb1");
    const EarliestOptions eo = earliest_options(toi_tolerance, first_window);
    const EarliestImpact e = workers_.run([&] {
      return with_points([&](const auto&... x) { return det_->earliest_impact(x..., eo); }, a0, a1,
                         b0, b1);
    });
    return earliest_tuple(e, true);
  }

  [[nodiscard]] py::array_t<int> edges_a() const { return edges_array(edges_a_); }
  [[nodiscard]] py::array_t<int> edges_b() const { return edges_array(edges_b_); }

 private:
  Workers workers_;
  std::vector<Edge> edges_a_, edges_b_;
  std::optional<PairDetector> det_;
};

py::tuple scene_tuple(research::ProceduralScene&& s) {
  return py::make_tuple(faces_array(std::move(s.faces)), matrix_array(s.v_t0),
                        matrix_array(s.v_t1));
}

constexpr const char* kOptionsDoc = R"(
Options (keyword-only):
  policy: cone policy, "provot" | "proposed" | "exact"; or, to reproduce the paper's
      measurements, "optimal" (the reference optimal cones; slow).
  culling: when a node's self test may be skipped, "none" | "sound" ("sound" finds exactly what
      "none" finds); or, to reproduce the paper's measurements, the unsound rules "cone" and
      "gated", which can miss collisions. Between two meshes only "none".
  bvh: tree build, "spatial" | "patch".
  thickness: contact distance of the kernels (>= 0); "sound" stays exact at any thickness.
  threads: worker threads (0: all cores).
  cull_min_triangles: "sound" tests only nodes of at least this many triangles (0: every node);
      the results are the same at any value, only the work changes (16 suits garments).
  np_filter, distance_filter, fast_path, toi_tolerance, distance_filter_depth, reuse_distance,
      reuse_front: as the C++ DetectOptions.)";

}  // namespace

void bind_detect(py::module_& m) {
  py::class_<SelfResult>(m, "DetectResult",
                         "Collisions of one step. vf: (k, 2) int32 (vertex, face); ee: (k, 2) "
                         "int32 (edge_a, edge_b), edge_a < edge_b, ids into the detector's edges; "
                         "*_toi: (k,) float64 times of impact in [0, 1], never late; stats: the "
                         "detector's counters and times (seconds).")
      .def_readonly("vf", &SelfResult::vf)
      .def_readonly("vf_toi", &SelfResult::vf_toi)
      .def_readonly("ee", &SelfResult::ee)
      .def_readonly("ee_toi", &SelfResult::ee_toi)
      .def_readonly("stats", &SelfResult::stats)
      .def_readonly("missed_vf", &SelfResult::missed_vf,
                    "With verify=True: VF pairs culling 'none' finds that this culling missed.")
      .def_readonly("missed_ee", &SelfResult::missed_ee)
      .def("__repr__", [](const SelfResult& r) {
        return fmt::format("<DetectResult: {} VF, {} EE>", r.vf.shape(0), r.ee.shape(0));
      });

  py::class_<ProximityOut>(m, "ProximityResult",
                           "Feature pairs closer than h: vf (vertex, face), ee (edge_a, edge_b), "
                           "each with its distance.")
      .def_readonly("vf", &ProximityOut::vf)
      .def_readonly("vf_distance", &ProximityOut::vf_distance)
      .def_readonly("ee", &ProximityOut::ee)
      .def_readonly("ee_distance", &ProximityOut::ee_distance)
      .def_readonly("reused_pairs", &ProximityOut::reused_pairs)
      .def("__repr__", [](const ProximityOut& r) {
        return fmt::format("<ProximityResult: {} VF, {} EE>", r.vf.shape(0), r.ee.shape(0));
      });

  py::class_<PairResult>(m, "PairDetectResult",
                         "Collisions between meshes A and B: vf_a_on_b (vertex of A, face of B), "
                         "vf_b_on_a (vertex of B, face of A), ee (edge of A, edge of B), each "
                         "with *_toi, and stats.")
      .def_readonly("vf_a_on_b", &PairResult::vf_a_on_b)
      .def_readonly("vf_a_on_b_toi", &PairResult::vf_a_on_b_toi)
      .def_readonly("vf_b_on_a", &PairResult::vf_b_on_a)
      .def_readonly("vf_b_on_a_toi", &PairResult::vf_b_on_a_toi)
      .def_readonly("ee", &PairResult::ee)
      .def_readonly("ee_toi", &PairResult::ee_toi)
      .def_readonly("stats", &PairResult::stats)
      .def("__repr__", [](const PairResult& r) {
        return fmt::format("<PairDetectResult: {} + {} VF, {} EE>", r.vf_a_on_b.shape(0),
                           r.vf_b_on_a.shape(0), r.ee.shape(0));
      });

  py::class_<PySelfDetector>(m, "SelfDetector",
                             (std::string(R"(Continuous self-collision detection of one mesh.

SelfDetector(F, V_rest, *, policy="proposed", culling="sound", bvh="patch", thickness=0.0,
             threads=0, linked_vertices=None, ...)

F: (m, 3) integer faces; V_rest: (n, 3) float positions the tree is split on (the rest shape or
the first frame). linked_vertices: optional (k, 2) vertex pairs that count as one point (a sewn
seam): pairs joining them are not tested.)") +
                              kOptionsDoc)
                                 .c_str())
      .def(py::init([](const ArrayLike& F, const ArrayLike& V, std::string policy,
                       std::string culling, std::string bvh, double thickness, int threads,
                       const ArrayLike& linked, bool np_filter, bool fast_path,
                       double toi_tolerance, int distance_filter_depth, double reuse_distance,
                       int cull_min_triangles, bool reuse_front, bool distance_filter) {
             OptionArgs a{policy,
                          culling,
                          thickness,
                          toi_tolerance,
                          reuse_distance,
                          np_filter,
                          fast_path,
                          distance_filter_depth,
                          cull_min_triangles,
                          reuse_front,
                          distance_filter};
             return std::make_unique<PySelfDetector>(F, V, bvh, a, threads, linked);
           }),
           py::arg("F"), py::arg("V_rest"), py::kw_only(), py::arg("policy") = "proposed",
           py::arg("culling") = "sound", py::arg("bvh") = "patch", py::arg("thickness") = 0.0,
           py::arg("threads") = 0, py::arg("linked_vertices") = py::none(),
           py::arg("np_filter") = true, py::arg("fast_path") = true,
           py::arg("toi_tolerance") = DetectOptions{}.toi_tolerance,
           py::arg("distance_filter_depth") = 0, py::arg("reuse_distance") = 0.0,
           py::arg("cull_min_triangles") = 0, py::arg("reuse_front") = false,
           py::arg("distance_filter") = DetectOptions{}.distance_filter)
      .def("detect", &PySelfDetector::detect, py::arg("V0"), py::arg("V1"),
           R"(All vertex-face and edge-edge pairs that touch while every vertex moves linearly
from V0 to V1 (both (n, 3)). Results are sorted and do not depend on the thread count. The GIL
is released while it runs.)")
      .def("earliest_impact", &PySelfDetector::earliest_impact, py::arg("V0"), py::arg("V1"),
           py::kw_only(), py::arg("toi_tolerance") = EarliestOptions{}.toi_tolerance,
           py::arg("first_window") = EarliestOptions{}.first_window,
           R"((toi, kind, ids): how far along V0 -> V1 every vertex-face and edge-edge pair stays
farther apart than the thickness. toi is never later than the first contact (moving to
V0 + toi (V1 - V0) is safe) and no more than toi_tolerance before the first time the reported pair
comes within the kernels' certified distance; kind is "vf" (ids: vertex, face), "ee" (ids: edge_a,
edge_b into `edges`) or "none" (toi 1, ids (-1, -1)). first_window: the first time window [0, T]
searched (a power of two; 0 picks it from the motion). Independent of the thread count; the GIL is
released while it runs.)")
      .def("proximity", &PySelfDetector::proximity, py::arg("V"), py::arg("h"),
           R"(Vertex-face and edge-edge pairs closer than h at positions V (boxes only, no cone
culling), with their distances.)")
      .def("set_active_vertices", &PySelfDetector::set_active_vertices, py::arg("ids"),
           R"(Restricts detection to pairs with at least one active vertex (the pairs whose motion
changes when only these vertices move).)")
      .def("set_active_faces", &PySelfDetector::set_active_faces, py::arg("ids"),
           "Restricts detection to pairs with a feature on one of these faces.")
      .def("clear_active", &PySelfDetector::clear_active, "Lifts an active restriction.")
      .def("rebuild", &PySelfDetector::rebuild, py::arg("V"),
           "Builds the tree afresh on positions V (results do not change; loose trees are slow).")
      .def(
          "set_options",
          [](PySelfDetector& d, std::optional<std::string> policy,
             std::optional<std::string> culling, std::optional<double> thickness,
             std::optional<bool> np_filter, std::optional<bool> fast_path,
             std::optional<double> toi_tolerance, std::optional<int> distance_filter_depth,
             std::optional<double> reuse_distance, std::optional<bool> verify,
             std::optional<int> cull_min_triangles, std::optional<bool> reuse_front,
             std::optional<bool> distance_filter) {
            d.set_options(OptionArgs{policy, culling, thickness, toi_tolerance, reuse_distance,
                                     np_filter, fast_path, distance_filter_depth,
                                     cull_min_triangles, reuse_front, distance_filter},
                          verify);
          },
          py::kw_only(), py::arg("policy") = py::none(), py::arg("culling") = py::none(),
          py::arg("thickness") = py::none(), py::arg("np_filter") = py::none(),
          py::arg("fast_path") = py::none(), py::arg("toi_tolerance") = py::none(),
          py::arg("distance_filter_depth") = py::none(), py::arg("reuse_distance") = py::none(),
          py::arg("verify") = py::none(), py::arg("cull_min_triangles") = py::none(),
          py::arg("reuse_front") = py::none(), py::arg("distance_filter") = py::none(),
          R"(Changes the options given (the tree build stays). verify=True also runs culling
"none" and reports what this culling missed in DetectResult.missed_vf / missed_ee.)")
      .def_property_readonly("edges", &PySelfDetector::edges,
                             "(e, 2) int32 unique edges (smaller id first), indexed by the ee "
                             "results' edge ids.")
      .def_property_readonly("faces", &PySelfDetector::faces_out, "(m, 3) int32 faces.")
      .def_property_readonly("num_vertices", &PySelfDetector::num_vertices)
      .def_property_readonly("options", &PySelfDetector::options, "The options as a dict.");

  py::class_<PyPairDetector>(m, "PairDetector",
                             (std::string(R"(Collisions between two meshes A and B (e.g. a
garment and a body), no self-collisions.

PairDetector(F_a, V_a, F_b, V_b, *, policy="proposed", culling="none", bvh="spatial",
             thickness=0.0, threads=0, ...)

V_a, V_b: (n, 3) reference positions the trees are split on.)") +
                              kOptionsDoc)
                                 .c_str())
      .def(py::init([](const ArrayLike& Fa, const ArrayLike& Va, const ArrayLike& Fb,
                       const ArrayLike& Vb, std::string policy, std::string culling,
                       std::string bvh, double thickness, int threads, bool np_filter,
                       bool fast_path, double toi_tolerance, int distance_filter_depth,
                       bool reuse_front, bool distance_filter) {
             OptionArgs a{policy,       culling,     thickness,      toi_tolerance,
                          std::nullopt, np_filter,   fast_path,      distance_filter_depth,
                          std::nullopt, reuse_front, distance_filter};
             return std::make_unique<PyPairDetector>(Fa, Va, Fb, Vb, bvh, a, threads);
           }),
           py::arg("F_a"), py::arg("V_a"), py::arg("F_b"), py::arg("V_b"), py::kw_only(),
           py::arg("policy") = "proposed", py::arg("culling") = "none", py::arg("bvh") = "spatial",
           py::arg("thickness") = 0.0, py::arg("threads") = 0, py::arg("np_filter") = true,
           py::arg("fast_path") = true, py::arg("toi_tolerance") = DetectOptions{}.toi_tolerance,
           py::arg("distance_filter_depth") = 0, py::arg("reuse_front") = false,
           py::arg("distance_filter") = DetectOptions{}.distance_filter)
      .def("detect", &PyPairDetector::detect, py::arg("Va0"), py::arg("Va1"), py::arg("Vb0"),
           py::arg("Vb1"),
           "Collisions while A moves linearly Va0 -> Va1 and B moves Vb0 -> Vb1 (GIL released).")
      .def("earliest_impact", &PyPairDetector::earliest_impact, py::arg("Va0"), py::arg("Va1"),
           py::arg("Vb0"), py::arg("Vb1"), py::kw_only(),
           py::arg("toi_tolerance") = EarliestOptions{}.toi_tolerance,
           py::arg("first_window") = EarliestOptions{}.first_window,
           R"((toi, kind, ids) between A and B, as SelfDetector.earliest_impact: kind "vf_a_on_b"
(ids: vertex of A, face of B), "vf_b_on_a", "ee" (edge of A, edge of B) or "none".)")
      .def_property_readonly("edges_a", &PyPairDetector::edges_a,
                             "(e, 2) int32 edges of A (the first column of ee indexes them).")
      .def_property_readonly("edges_b", &PyPairDetector::edges_b, "(e, 2) int32 edges of B.");

  auto proc = m.def_submodule(
      "procedural",
      "Small procedural scenes with one linear motion each (tests, examples): each function "
      "returns (F, V0, V1).");
  proc.def(
      "stacked_sheets", [](int n) { return scene_tuple(research::stacked_sheets(n)); },
      py::arg("n") = 12, "Two n x n sheets 0.1 apart moving through each other.");
  proc.def(
      "winding_strip",
      [](int segments, int rings) { return scene_tuple(research::winding_strip(segments, rings)); },
      py::arg("segments") = 96, py::arg("rings") = 3,
      "An annular strip over 2 pi + 1 radians whose overlapping ends pass through each other.");
  proc.def(
      "crumpled_sheet",
      [](int n, std::uint64_t seed) { return scene_tuple(research::crumpled_sheet(n, seed)); },
      py::arg("n"), py::arg("seed"), "An n x n sheet crumpled by a random smooth displacement.");
  proc.def(
      "twisted_strip",
      [](int segments, int width) { return scene_tuple(research::twisted_strip(segments, width)); },
      py::arg("segments") = 80, py::arg("width") = 4,
      "A strip, twisted and coiled so that its ends cross.");
  proc.def(
      "smooth_perturbation",
      [](const ArrayLike& V, double amplitude, double wavelength, std::uint64_t seed) {
        return matrix_array(
            research::smooth_perturbation(positions(V, "V"), amplitude, wavelength, seed));
      },
      py::arg("V"), py::arg("amplitude"), py::arg("wavelength"), py::arg("seed"),
      "V plus a smooth displacement field (no coordinate moves more than amplitude).");
}

}  // namespace clothcd::python
