// Inter-object detection between two meshes (garment against body): pair traversal of the two
// BVHs, then each VF / EE feature pair tested once, at the pair of the features' first faces,
// through the same feature boxes, filters and kernels as the self detector (narrow.hpp).

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string_view>

#include "bvh/front.hpp"
#include "bvh/traversal.hpp"
#include "ccd/batch.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/names.hpp"
#include "earliest.hpp"
#include "mesh_state.hpp"
#include "narrow.hpp"
#include "options.hpp"
#include "pair_loop.hpp"
#include "pair_results.hpp"
#include "positions.hpp"

namespace clothcd {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Options the two-mesh detector cannot honour are refused before any work.
void check_pair_options(const DetectOptions& o) {
  if (o.culling != Culling::None) {
    throw InputError(
        "PairDetector: normal cones cull self-collision tests only; use Culling::None between "
        "two meshes");
  }
  if (o.reuse_distance != 0.0) {
    throw InputError(fmt::format("PairDetector: reuse_distance is not supported (got {}); use 0",
                                 o.reuse_distance));
  }
  if (!o.linked_vertices.empty()) {
    throw InputError(
        "PairDetector: linked_vertices join vertices of one mesh; no pair between "
        "two meshes can hold two of them");
  }
  detail::check_common_options(o);
}

// The feature pairs of one leaf pair (fa, fb) that it represents (their features' first faces
// are fa and fb) and that the scope keeps, past the feature box test: vf(v, f) with a vertex of
// A and a face of B, fv(u, f) with a vertex of B and a face of A, ee(a, b).
template <class InScope, class Vf, class Fv, class Ee>
void face_pair(const detail::FeatureContext& ca, const detail::FeatureContext& cb, int fa, int fb,
               InScope&& in_scope, Vf&& vf, Fv&& fv, Ee&& ee) {
  const Topology& ta = *ca.topo;
  const Topology& tb = *cb.topo;
  const detail::Box& box_a = ca.fboxes[fa];
  const detail::Box& box_b = cb.fboxes[fb];
  for (int v : ta.faces()[fa]) {
    if (ta.vertex_faces(v)[0] != fa || !detail::overlap(ca.vboxes[v], box_b)) continue;
    if (in_scope.vf(v, fb)) vf(v, fb);
  }
  for (int u : tb.faces()[fb]) {
    if (tb.vertex_faces(u)[0] != fb || !detail::overlap(cb.vboxes[u], box_a)) continue;
    if (in_scope.fv(u, fa)) fv(u, fa);
  }
  for (int ea : ta.face_edges(fa)) {
    if (ta.edge_faces(ea)[0] != fa) continue;
    const detail::Box& xa = ca.eboxes[ea];
    if (!detail::overlap(xa, box_b)) continue;  // the edge misses all of fb
    for (int eb : tb.face_edges(fb)) {
      if (tb.edge_faces(eb)[0] != fb || !detail::overlap(xa, cb.eboxes[eb])) continue;
      if (in_scope.ee(ea, eb)) ee(ea, eb);
    }
  }
}

struct Buffer : detail::LoopBuffers {
  // Feature pairs waiting for the batch filters: A's vertices against B's faces and the edge
  // pairs in `queued`, B's vertices against A's faces in `queued_ba` (its vf part).
  detail::FeatureBatch queued, queued_ba;
  std::vector<VertexFaceCollision> ab, ba;
  std::vector<EdgeEdgeCollision> ee;
};

// The pair loop's side of mesh m under context c (no face blocks: the feature tests read the
// plain boxes).
detail::LoopSide loop_side(const detail::MeshState& m, const detail::FeatureContext& c) {
  return {m.v0, m.v1, &m.topo.faces(), {}, c.fboxes};
}
// The two-mesh loop reads its boxes in the order of its pairs: nothing to fetch ahead.
constexpr auto no_fetch = [](int, int) {};

template <class Item>
void sort_by_ids(std::vector<Item>& v) {
  std::sort(v.begin(), v.end(), [](const Item& x, const Item& y) {
    if constexpr (requires { x.vertex; }) {
      return std::pair(x.vertex, x.face) < std::pair(y.vertex, y.face);
    } else {
      return std::pair(x.edge_a, x.edge_b) < std::pair(y.edge_a, y.edge_b);
    }
  });
}

}  // namespace

struct PairDetector::Impl {
  DetectOptions opt;
  detail::MeshState a, b;  // no cones: they cannot cull between meshes
  // The active restriction, set on both meshes at once.
  [[nodiscard]] bool restricted() const { return a.restricted; }

  Impl(std::vector<Face> fa, int na, detail::PointsIn ra, std::vector<Face> fb, int nb,
       detail::PointsIn rb, const DetectOptions& o)
      : opt((check_pair_options(o), o)),
        a(std::move(fa), na, ra, "reference shape A", o.build, false, false),
        b(std::move(fb), nb, rb, "reference shape B", o.build, false, false) {}

  // The active restriction: a VF pair when its vertex or a vertex of its face is active, an EE
  // pair when an endpoint is active (SelfDetector::set_active_vertices across two meshes).
  struct Scope {
    const Impl& m;
    [[nodiscard]] bool vf(int v, int f) const {
      return !m.restricted() || m.a.vertex_active[v] != 0 || m.b.face_active[f] != 0;
    }
    [[nodiscard]] bool fv(int u, int f) const {
      return !m.restricted() || m.b.vertex_active[u] != 0 || m.a.face_active[f] != 0;
    }
    [[nodiscard]] bool ee(int ea, int eb) const {
      return !m.restricted() || m.a.edge_active[ea] != 0 || m.b.edge_active[eb] != 0;
    }
  };

  // The traversal's output, kept from call to call so that a simulation's calls reuse its
  // memory (fresh vectors of this size come from the system, page by page, at every call).
  struct Pairs {
    std::vector<std::pair<int, int>> v;
  };
  tbb::enumerable_thread_specific<Pairs> pair_locals;
  // Where the last unrestricted detect() with opt.reuse_front stopped (front.hpp).
  detail::TraversalFront front;

  // Overlapping leaf pairs (face of A, face of B), below active nodes when restricted; valid
  // until the next call. `from_front`: start from the front (unrestricted calls only), and keep
  // the new one.
  detail::PairList traverse(DetectStats& st, bool from_front = false) {
    detail::PairList pairs;
    const auto& na = a.bvh.nodes();
    const auto& nb = b.bvh.nodes();
    if (na.empty() || nb.empty()) return pairs;
    const auto& pa = a.bvh.prim_ids();
    const auto& pb = b.bvh.prim_ids();
    auto leaf = [&](int x, int y, Pairs& out) {
      out.v.emplace_back(pa[na[x].first], pb[nb[y].first]);
    };
    for (auto& l : pair_locals)
      l.v.clear();
    if (from_front) {
      if (front.empty()) {
        const detail::TraversalFront::Root root{0, 0, 0};
        front.seed({&root, 1});
      }
      st.box_tests = front.run(
          a.bvh, b.bvh, [](int) { return true; }, leaf, pair_locals);
      st.front_pairs = front.size();
    } else {
      auto tr = detail::make_traversal(
          std::span<const BvhNode>(na), std::span<const BvhNode>(nb), a.active_nodes(),
          b.active_nodes(), [](int, detail::TraversalCounters&) { return false; }, leaf);
      st.box_tests = detail::run_parallel(tr, {0, 0, false}, pair_locals).box_tests;
    }
    for (const auto& l : pair_locals)
      pairs.add(l.v);
    return pairs;
  }

  // `kernels` false: every pair the filters keep is a hit at time 0 (the earliest-impact
  // query's windows).
  PairDetectResult detect(detail::PointsIn a_t0, detail::PointsIn a_t1, detail::PointsIn b_t0,
                          detail::PointsIn b_t1, bool kernels = true) {
    a.step.update(a_t0, a_t1, a.topo.num_vertices(), "mesh A at t0", "mesh A at t1");
    b.step.update(b_t0, b_t1, b.topo.num_vertices(), "mesh B at t0", "mesh B at t1");
    auto t = Clock::now();
    RefitOptions ro;
    ro.thickness = opt.thickness;
    ro.cones = false;
    a.sweep(ro);
    b.sweep(ro);
    const double t_refit = seconds_since(t);

    t = Clock::now();
    DetectStats st;
    const detail::PairList pairs = traverse(st, opt.reuse_front && !restricted());
    const double t_trav = seconds_since(t);

    t = Clock::now();
    detail::FeatureContext ca = detail::ccd_context(a.topo, a.v0, a.v1, opt);
    ca.plan.kernel = kernels;
    detail::FeatureContext cb = detail::ccd_context(b.topo, b.v0, b.v1, opt);
    a.boxes.update(ca, a.step);
    b.boxes.update(cb, b.step);
    tbb::enumerable_thread_specific<Buffer> locals;
    const Scope scope{*this};
    const bool batched = ca.plan.faces_apart;
    // Both contexts have the same settings; ca's filters and kernels test every feature pair.
    const auto& faces_a = a.topo.faces();
    const auto& faces_b = b.topo.faces();
    const auto& edges_a = a.topo.edges();
    const auto& edges_b = b.topo.edges();
    // The VF pairs queued in q (vertices of one mesh against `faces` of the other) into `hits`.
    const auto flush_vf = [&](Buffer& out, detail::FeatureBatch& q, const std::vector<Face>& faces,
                              std::vector<VertexFaceCollision>& hits) {
      ca.flush_queries(ccd_detail::Kind::VertexFace, q.vf, q, out.c.vf_tests, out.c.vf_np,
                       [&](int i, double toi) {
                         const auto [v, f] = q.vf_ids[i];
                         hits.push_back({v, f, faces[f], toi});
                       });
    };
    const auto flush_ab = [&](Buffer& out) { flush_vf(out, out.queued, faces_b, out.ab); };
    const auto flush_ba = [&](Buffer& out) { flush_vf(out, out.queued_ba, faces_a, out.ba); };
    const auto flush_ee = [&](Buffer& out) {
      ca.flush_queries(ccd_detail::Kind::EdgeEdge, out.queued.ee, out.queued, out.c.ee_tests,
                       out.c.ee_np, [&](int i, double toi) {
                         const auto [ea, eb] = out.queued.ee_ids[i];
                         out.ee.push_back({ea, eb, edges_a[ea], edges_b[eb], toi});
                       });
    };
    detail::LoopPlan plan;
    plan.filter = batched ? detail::TriangleFilter::Swept : detail::TriangleFilter::None;
    plan.distance = opt.thickness;
    pair_loop(pairs, loop_side(a, ca), loop_side(b, cb), plan, locals, no_fetch,
              [&](int fa, int fb, Buffer& out) {
                face_pair(
                    ca, cb, fa, fb, scope,
                    [&](int v, int f) {
                      if (out.queued.push_vf({v, f}, ca.vf_points(v, cb, faces_b[f])))
                        flush_ab(out);
                    },
                    [&](int u, int f) {
                      if (out.queued_ba.push_vf({u, f}, cb.vf_points(u, ca, faces_a[f])))
                        flush_ba(out);
                    },
                    [&](int ea, int eb) {
                      if (out.queued.push_ee({ea, eb}, ca.ee_points(edges_a[ea], cb, edges_b[eb])))
                        flush_ee(out);
                    });
              });
    for (auto& out : locals) {  // at most one partial batch of each kind per thread
      flush_ab(out);
      flush_ba(out);
      flush_ee(out);
    }
    PairDetectResult res = detail::collect_pair_results(locals);
    res.stats.box_tests = st.box_tests;
    res.stats.front_pairs = st.front_pairs;
    res.stats.triangle_pairs = pairs.size();
    res.stats.time_refit = t_refit;
    res.stats.time_traverse = t_trav;
    res.stats.time_narrow = seconds_since(t);
    return res;
  }

  EarliestImpact earliest_impact(detail::PointsIn pa0, detail::PointsIn pa1, detail::PointsIn pb0,
                                 detail::PointsIn pb1, const EarliestOptions& eo) {
    detail::check_earliest_options(eo);
    std::vector<Eigen::Vector3d> x[4], as, at, bs, bt;
    detail::to_points(pa0, a.topo.num_vertices(), "mesh A at t0", x[0]);
    detail::to_points(pa1, a.topo.num_vertices(), "mesh A at t1", x[1]);
    detail::to_points(pb0, b.topo.num_vertices(), "mesh B at t0", x[2]);
    detail::to_points(pb1, b.topo.num_vertices(), "mesh B at t1", x[3]);
    using Points = std::span<const Eigen::Vector3d>;
    const Topology* const meshes[] = {&a.topo, &b.topo};
    const Points s0[] = {x[0], x[2]}, s1[] = {x[1], x[3]};
    const double first = detail::first_window(eo, meshes, s0, s1);
    const double slack =
        std::max(detail::rounding_slack(x[0], x[1]), detail::rounding_slack(x[2], x[3]));
    const auto& fa = a.topo.faces();
    const auto& fb = b.topo.faces();
    const auto& ea = a.topo.edges();
    const auto& eb = b.topo.edges();
    // A vertex of one mesh against a face of the other (vertex_on_b: of B against A).
    const auto make_vf = [&](int v, int f, bool on_b) {
      const auto& p0 = on_b ? x[2] : x[0];
      const auto& p1 = on_b ? x[3] : x[1];
      const auto& q0 = on_b ? x[0] : x[2];
      const auto& q1 = on_b ? x[1] : x[3];
      const Face& t = on_b ? fa[f] : fb[f];
      return VertexFaceQuery{p0[v], q0[t[0]], q0[t[1]], q0[t[2]],
                             p1[v], q1[t[0]], q1[t[1]], q1[t[2]]};
    };
    const auto make_ee = [&](int i, int j) {
      const Edge &p = ea[i], &q = eb[j];
      return EdgeEdgeQuery{x[0][p[0]], x[0][p[1]], x[2][q[0]], x[2][q[1]],
                           x[1][p[0]], x[1][p[1]], x[3][q[0]], x[3][q[1]]};
    };
    detail::EarliestSearch search(detail::ccd_context(a.topo, x[0], x[1], opt).ccd,
                                  eo.toi_tolerance, make_vf, make_ee);
    const DetectOptions saved = opt;
    struct Restore {
      Impl& m;
      const DetectOptions& saved;
      ~Restore() { m.opt = saved; }
    } restore{*this, saved};
    return detail::search_windows(
        first, slack, search, [&](double lo, double hi, double sl, DetectStats& stats) {
          const bool whole = lo == 0 && hi == 1;
          opt = detail::window_options(saved, sl, search.kernel().toi_tolerance);
          if (lo > 0) {
            detail::interpolate(x[0], x[1], lo, as);
            detail::interpolate(x[2], x[3], lo, bs);
          }
          if (hi < 1) {
            detail::interpolate(x[0], x[1], hi, at);
            detail::interpolate(x[2], x[3], hi, bt);
          }
          const PairDetectResult r =
              detect(Points(lo > 0 ? as : x[0]), Points(hi < 1 ? at : x[1]),
                     Points(lo > 0 ? bs : x[2]), Points(hi < 1 ? bt : x[3]), whole);
          detail::add_stats(r.stats, stats);
          search.add(r.vf_a_on_b, r.ee, false);
          search.add(r.vf_b_on_a, {}, true);
        });
  }

  PairProximityResult proximity(detail::PointsIn pa, detail::PointsIn pb, double h) {
    if (!(h >= 0) || !std::isfinite(h)) {
      throw InputError(fmt::format("proximity distance must be finite and >= 0, got {}", h));
    }
    a.step.update_static(pa, a.topo.num_vertices(), "mesh A positions");
    b.step.update_static(pb, b.topo.num_vertices(), "mesh B positions");
    a.refit_static(h);
    b.refit_static(h);
    DetectStats st;
    const detail::PairList pairs = traverse(st);
    detail::FeatureContext ca = detail::proximity_context(a.topo, a.v0, h);
    detail::FeatureContext cb = detail::proximity_context(b.topo, b.v0, h);
    a.boxes.update(ca, a.step);
    b.boxes.update(cb, b.step);
    const auto& faces_a = a.topo.faces();
    const auto& faces_b = b.topo.faces();
    const auto& edges_a = a.topo.edges();
    const auto& edges_b = b.topo.edges();
    struct Found : detail::LoopBuffers {
      std::vector<ProximityResult::VertexFace> ab, ba;
      std::vector<ProximityResult::EdgeEdge> ee;
    };
    tbb::enumerable_thread_specific<Found> locals;
    const Scope scope{*this};
    const auto& xa = a.v0;
    const auto& xb = b.v0;
    // No feature pair is closer than the whole triangles' bound.
    detail::LoopPlan plan;
    plan.filter = detail::TriangleFilter::Static;
    plan.distance = h;
    pair_loop(pairs, loop_side(a, ca), loop_side(b, cb), plan, locals, no_fetch,
              [&](int f, int g, Found& out) {
                face_pair(
                    ca, cb, f, g, scope,
                    [&](int v, int k) {
                      const Face& t = faces_b[k];
                      const double d =
                          ccd_detail::point_triangle_within(xa[v], xb[t[0]], xb[t[1]], xb[t[2]], h);
                      if (d <= h) out.ab.push_back({v, k, d});
                    },
                    [&](int u, int k) {
                      const Face& t = faces_a[k];
                      const double d =
                          ccd_detail::point_triangle_within(xb[u], xa[t[0]], xa[t[1]], xa[t[2]], h);
                      if (d <= h) out.ba.push_back({u, k, d});
                    },
                    [&](int x, int y) {
                      const Edge &p = edges_a[x], &q = edges_b[y];
                      const double d =
                          ccd_detail::edge_edge_within(xa[p[0]], xa[p[1]], xb[q[0]], xb[q[1]], h);
                      if (d <= h) out.ee.push_back({x, y, d});
                    });
              });
    PairProximityResult res;
    for (const auto& l : locals) {
      res.vf_a_on_b.insert(res.vf_a_on_b.end(), l.ab.begin(), l.ab.end());
      res.vf_b_on_a.insert(res.vf_b_on_a.end(), l.ba.begin(), l.ba.end());
      res.ee.insert(res.ee.end(), l.ee.begin(), l.ee.end());
    }
    sort_by_ids(res.vf_a_on_b);
    sort_by_ids(res.vf_b_on_a);
    sort_by_ids(res.ee);
    return res;
  }
};

namespace {
// PairDetector::rebuild for either input form.
template <class Impl>
void rebuild_detector(Impl& m, detail::PointsIn reference_a, detail::PointsIn reference_b) {
  std::vector<Eigen::Vector3d> ra, rb;
  detail::to_points(reference_a, m.a.topo.num_vertices(), "reference shape A", ra);
  detail::to_points(reference_b, m.b.topo.num_vertices(), "reference shape B", rb);
  // Both references are checked before either tree changes.
  m.a.rebuild(std::span<const Eigen::Vector3d>(ra), "reference shape A", m.opt.build, false);
  m.b.rebuild(std::span<const Eigen::Vector3d>(rb), "reference shape B", m.opt.build, false);
  m.front.clear();  // the front's node pairs belonged to the old trees
}
}  // namespace

PairDetector::PairDetector(std::vector<Face> faces_a, int num_vertices_a,
                           const Positions& reference_a, std::vector<Face> faces_b,
                           int num_vertices_b, const Positions& reference_b,
                           const DetectOptions& options)
    : impl_(std::make_unique<Impl>(std::move(faces_a), num_vertices_a, reference_a,
                                   std::move(faces_b), num_vertices_b, reference_b, options)) {}
PairDetector::PairDetector(std::vector<Face> faces_a, int num_vertices_a,
                           std::span<const Eigen::Vector3d> reference_a, std::vector<Face> faces_b,
                           int num_vertices_b, std::span<const Eigen::Vector3d> reference_b,
                           const DetectOptions& options)
    : impl_(std::make_unique<Impl>(std::move(faces_a), num_vertices_a, reference_a,
                                   std::move(faces_b), num_vertices_b, reference_b, options)) {}
PairDetector::PairDetector(const Eigen::Ref<const Eigen::MatrixX3i>& faces_a,
                           const Positions& reference_a,
                           const Eigen::Ref<const Eigen::MatrixX3i>& faces_b,
                           const Positions& reference_b, const DetectOptions& options)
    : impl_(std::make_unique<Impl>(to_faces(faces_a), static_cast<int>(reference_a.rows()),
                                   reference_a, to_faces(faces_b),
                                   static_cast<int>(reference_b.rows()), reference_b, options)) {}
PairDetector::~PairDetector() = default;
PairDetector::PairDetector(PairDetector&&) noexcept = default;
PairDetector& PairDetector::operator=(PairDetector&&) noexcept = default;

PairDetectResult PairDetector::detect(const Positions& a_t0, const Positions& a_t1,
                                      const Positions& b_t0, const Positions& b_t1) {
  return impl_->detect(a_t0, a_t1, b_t0, b_t1);
}
PairDetectResult PairDetector::detect(std::span<const Eigen::Vector3d> a_t0,
                                      std::span<const Eigen::Vector3d> a_t1,
                                      std::span<const Eigen::Vector3d> b_t0,
                                      std::span<const Eigen::Vector3d> b_t1) {
  return impl_->detect(a_t0, a_t1, b_t0, b_t1);
}
PairProximityResult PairDetector::proximity(const Positions& a, const Positions& b, double h) {
  return impl_->proximity(a, b, h);
}
PairProximityResult PairDetector::proximity(std::span<const Eigen::Vector3d> a,
                                            std::span<const Eigen::Vector3d> b, double h) {
  return impl_->proximity(a, b, h);
}
EarliestImpact PairDetector::earliest_impact(const Positions& a_t0, const Positions& a_t1,
                                             const Positions& b_t0, const Positions& b_t1,
                                             const EarliestOptions& options) {
  return impl_->earliest_impact(a_t0, a_t1, b_t0, b_t1, options);
}
EarliestImpact PairDetector::earliest_impact(std::span<const Eigen::Vector3d> a_t0,
                                             std::span<const Eigen::Vector3d> a_t1,
                                             std::span<const Eigen::Vector3d> b_t0,
                                             std::span<const Eigen::Vector3d> b_t1,
                                             const EarliestOptions& options) {
  return impl_->earliest_impact(a_t0, a_t1, b_t0, b_t1, options);
}
void PairDetector::set_active_vertices(std::span<const int> vertices_a,
                                       std::span<const int> vertices_b) {
  Impl& m = *impl_;
  m.a.set_active_vertices(vertices_a, "A");
  try {
    m.b.set_active_vertices(vertices_b, "B");
  } catch (...) {
    m.a.clear_active();  // the restriction holds on both meshes or on neither
    throw;
  }
}
void PairDetector::clear_active() {
  impl_->a.clear_active();
  impl_->b.clear_active();
}
void PairDetector::rebuild(const Positions& reference_a, const Positions& reference_b) {
  rebuild_detector(*impl_, reference_a, reference_b);
}
void PairDetector::rebuild(std::span<const Eigen::Vector3d> reference_a,
                           std::span<const Eigen::Vector3d> reference_b) {
  rebuild_detector(*impl_, reference_a, reference_b);
}
const DetectOptions& PairDetector::options() const {
  return impl_->opt;
}
void PairDetector::set_options(const DetectOptions& options) {
  check_pair_options(options);
  if (options.build != impl_->opt.build) {
    throw InputError(fmt::format(
        "PairDetector::set_options: the BVH build is fixed at construction ({}), got {}; "
        "construct a detector for another build",
        to_string(impl_->opt.build), to_string(options.build)));
  }
  impl_->opt = options;
  if (!options.reuse_front) impl_->front.clear();
}
const Topology& PairDetector::topology_a() const {
  return impl_->a.topo;
}
const Topology& PairDetector::topology_b() const {
  return impl_->b.topo;
}
const Bvh& PairDetector::bvh_a() const {
  return impl_->a.bvh;
}
const Bvh& PairDetector::bvh_b() const {
  return impl_->b.bvh;
}

}  // namespace clothcd
