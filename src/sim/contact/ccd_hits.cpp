// CCD hits of the substep's motion, settled into contacts.
#include "sim/contact/ccd_hits.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

#include "clothcd/ccd/proximity.hpp"
#include "clothcd/ccd/queries.hpp"
#include "sim/contact/part_clock.hpp"

namespace clothcd::sim::detail {
namespace {

CcdResult kernel(const VertexFaceQuery& q, const CcdOptions& o) {
  return vertex_face_ccd(q, o);
}
CcdResult kernel(const EdgeEdgeQuery& q, const CcdOptions& o) {
  return edge_edge_ccd(q, o);
}

// f(i) for i in [0, n) in parallel, in index order.
template <class F>
auto map_parallel(std::size_t n, F&& f) {
  std::vector<decltype(f(std::size_t{0}))> out(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        out[i] = f(i);
                    });
  return out;
}

constexpr double kNoReach = std::numeric_limits<double>::infinity();

}  // namespace

CcdPass CcdHits::find(std::span<const Vec3> v, const std::vector<int>* active, double sep_scale,
                      bool self, bool body) {
  CcdPass out;
  double all = 0.0;
  {
    PartClock clock(all);
    std::vector<Vec3> x1(g_.x0.size());
    for (std::size_t i = 0; i < g_.x0.size(); ++i)
      x1[i] = g_.x0[i] + g_.h * v[i];
    if (self) self_hits(x1, v, active, sep_scale, out);
    if (body) body_hits(x1, v, active, sep_scale, out);
  }
  // Everything but the detector calls counts as turning hits into contacts.
  out.times.ccd_hits_s = all - (out.times.ccd_self_s + out.times.ccd_body_s);
  return out;
}

// The CCD separation of a pair at distance d0 at t0: the configured one, or half the start
// distance for pairs already closer than twice it (resting contact). A pair inside its own
// separation at t0 would otherwise be a hit at toi 0 that no non-approaching velocity removes.
// Negative: the pair touches at t0 and is left to repulsion.
double CcdHits::separation(double d0, double sep_scale) const {
  if (!(d0 > 0.0)) return -1.0;
  return sep_scale * std::min(opt_.ccd_thickness, 0.5 * d0);
}

// Dropped pairs (an escaping vertex's body pairs; the detector leaves seam-linked ones out) are
// dropped; tangled pairs and pairs touching at t0 are excluded (left to repulsion); a pair
// farther apart at t0 (d0()) than `reach` (what both sides move plus the separation) cannot
// touch; a resting pair, closer at t0 than twice the CCD separation, is retested at its own
// separation (see separation()); the rest become contacts at the detector's time of impact. The
// response needs the first contact only roughly (impulses use the geometry at toi), so the
// retest's kernel, like the detector's, stops refining it at `toi_tolerance` (on the early
// side).
template <class Query, class Distance, class Make>
CcdHits::Hit CcdHits::settle(double sep_scale, bool dropped, bool tangled, double toi,
                             const Query& query, Distance&& d0, Make&& make, double reach) const {
  Hit r;
  if (dropped) return r;
  if (tangled) {
    r.fate = Hit::Excluded;
    return r;
  }
  const double d = d0();
  if (d > reach) return r;
  const double s = separation(d, sep_scale);
  if (s < 0) {
    r.fate = Hit::Excluded;
    return r;
  }
  if (s < opt_.ccd_thickness) {
    if (distance_filter_culls(query, s, opt_.distance_filter_depth)) return r;
    CcdOptions o;
    o.thickness = s;
    o.toi_tolerance = opt_.toi_tolerance;
    const CcdResult rr = kernel(query, o);
    if (!rr.hit) return r;
    toi = rr.toi;
  }
  if (make(r.contact, toi)) {
    r.contact.sep = s;
    r.fate = Hit::Kept;
  }
  return r;
}

void CcdHits::self_hits(std::span<const Vec3> x1, std::span<const Vec3> v,
                        const std::vector<int>* active, double sep_scale, CcdPass& out) {
  if (active == nullptr && opt_.on_full_self_pass) opt_.on_full_self_pass(g_.x0, x1);
  // The restriction to the active vertices is the detector's work too.
  const DetectResult r = [&] {
    PartClock clock(out.times.ccd_self_s);
    return det_.self_ccd(g_, x1, active);
  }();
  if (active == nullptr) {
    SelfCcdFigures& f = out.self_ccd;
    f.calls = 1;
    f.triangle_pairs = static_cast<long long>(r.stats.triangle_pairs);
    f.nodes_culled = static_cast<long long>(r.stats.nodes_culled);
    f.refit_s = r.stats.time_refit;
    f.traversal_s = r.stats.time_traverse;
    f.narrow_s = r.stats.time_narrow;
  }
  // Each hit in parallel; the contacts are then gathered in the detector's sorted order.
  const auto& faces = g_.cloth().faces();
  const auto& edges = g_.cloth().edges();
  const auto& x0 = g_.x0;
  const std::vector<Hit> vf = map_parallel(r.vf.size(), [&](std::size_t i) {
    const VertexFaceCollision& p = r.vf[i];
    const Face& t = faces[p.face];
    const int q = p.vertex;
    const VertexFaceQuery query{x0[q], x0[t[0]], x0[t[1]], x0[t[2]],
                                x1[q], x1[t[0]], x1[t[1]], x1[t[2]]};
    return settle(
        sep_scale, false, crossings_.vf_tangled(g_.cloth(), q, p.face), p.toi, query,
        [&] { return point_triangle_proximity(x0[q], x0[t[0]], x0[t[1]], x0[t[2]]).distance; },
        [&](Contact& c, double toi) { return g_.make_vf(c, q, false, p.face, false, toi, v); },
        kNoReach);
  });
  const std::vector<Hit> ee = map_parallel(r.ee.size(), [&](std::size_t i) {
    const EdgeEdgeCollision& p = r.ee[i];
    const Edge& a = edges[p.edge_a];
    const Edge& b = edges[p.edge_b];
    const EdgeEdgeQuery query{x0[a[0]], x0[a[1]], x0[b[0]], x0[b[1]],
                              x1[a[0]], x1[a[1]], x1[b[0]], x1[b[1]]};
    return settle(
        sep_scale, false, crossings_.ee_tangled(g_.cloth(), p.edge_a, p.edge_b), p.toi, query,
        [&] { return edge_edge_proximity(x0[a[0]], x0[a[1]], x0[b[0]], x0[b[1]]).distance; },
        [&](Contact& c, double toi) {
          return g_.make_ee(c, p.edge_a, false, p.edge_b, false, toi, v);
        },
        kNoReach);
  });
  gather({&vf, &ee}, out);
}

// Cloth-body hits, each settled like a self hit. Its distance at t0 is measured within the reach
// of the pair's motion (a pair farther apart cannot touch), the measure the separation of a
// resting pair is taken from.
void CcdHits::body_hits(std::span<const Vec3> x1, std::span<const Vec3> v,
                        const std::vector<int>* active, double sep_scale, CcdPass& out) {
  const PairDetectResult r = [&] {
    PartClock clock(out.times.ccd_body_s);
    return det_.body_ccd(g_, x1, active);
  }();
  const auto& cf = g_.cloth().faces();
  const auto& bf = g_.body().faces();
  const auto& ce = g_.cloth().edges();
  const auto& be = g_.body().edges();
  const auto& x0 = g_.x0;
  const auto& b0 = g_.b0;
  const auto& b1 = g_.b1;
  const double sep = opt_.ccd_thickness;
  auto move_c = [&](int i) { return (x1[i] - x0[i]).norm(); };
  auto move_b = [&](int i) { return (b1[i] - b0[i]).norm(); };
  const std::vector<Hit> cb = map_parallel(r.vf_a_on_b.size(), [&](std::size_t k) {
    const VertexFaceCollision& p = r.vf_a_on_b[k];
    const int i = p.vertex;
    const Face& t = bf[p.face];
    const double reach = move_c(i) + std::max({move_b(t[0]), move_b(t[1]), move_b(t[2])}) + sep;
    return settle(
        sep_scale, escapes_.vertex(i), crossings_.cloth_vertex_body_face(g_, i, p.face), p.toi,
        VertexFaceQuery{x0[i], b0[t[0]], b0[t[1]], b0[t[2]], x1[i], b1[t[0]], b1[t[1]], b1[t[2]]},
        [&] {
          return point_triangle_distance_if_within(x0[i], b0[t[0]], b0[t[1]], b0[t[2]], reach);
        },
        [&](Contact& c, double toi) { return g_.make_vf(c, i, false, p.face, true, toi, v); },
        reach);
  });
  const std::vector<Hit> bc = map_parallel(r.vf_b_on_a.size(), [&](std::size_t k) {
    const VertexFaceCollision& p = r.vf_b_on_a[k];
    const int u = p.vertex;
    const Face& t = cf[p.face];
    const double reach = move_b(u) + std::max({move_c(t[0]), move_c(t[1]), move_c(t[2])}) + sep;
    return settle(
        sep_scale, escapes_.face(t), crossings_.body_vertex_cloth_face(g_, u, p.face), p.toi,
        VertexFaceQuery{b0[u], x0[t[0]], x0[t[1]], x0[t[2]], b1[u], x1[t[0]], x1[t[1]], x1[t[2]]},
        [&] {
          return point_triangle_distance_if_within(b0[u], x0[t[0]], x0[t[1]], x0[t[2]], reach);
        },
        [&](Contact& c, double toi) { return g_.make_vf(c, u, true, p.face, false, toi, v); },
        reach);
  });
  const std::vector<Hit> ee = map_parallel(r.ee.size(), [&](std::size_t k) {
    const EdgeEdgeCollision& p = r.ee[k];
    const Edge& x = ce[p.edge_a];
    const Edge& y = be[p.edge_b];
    const double reach =
        std::max(move_c(x[0]), move_c(x[1])) + std::max(move_b(y[0]), move_b(y[1])) + sep;
    return settle(
        sep_scale, escapes_.edge(x), crossings_.cloth_edge_body_edge(g_, p.edge_a, p.edge_b), p.toi,
        EdgeEdgeQuery{x0[x[0]], x0[x[1]], b0[y[0]], b0[y[1]], x1[x[0]], x1[x[1]], b1[y[0]],
                      b1[y[1]]},
        [&] { return edge_edge_distance_if_within(x0[x[0]], x0[x[1]], b0[y[0]], b0[y[1]], reach); },
        [&](Contact& c, double toi) {
          return g_.make_ee(c, p.edge_a, false, p.edge_b, true, toi, v);
        },
        reach);
  });
  gather({&cb, &bc, &ee}, out);
}

// The kept contacts of settled hits in order; excluded ones are counted.
void CcdHits::gather(std::initializer_list<const std::vector<Hit>*> lists, CcdPass& out) {
  for (const auto* l : lists) {
    for (const Hit& hit : *l) {
      if (hit.fate == Hit::Excluded) ++out.excluded;
      if (hit.fate == Hit::Kept) out.contacts.push_back(hit.contact);
    }
  }
}

}  // namespace clothcd::sim::detail
