// The earliest-impact query (earliest.hpp): the window rule, and the self detector's windows as
// detections of its own pipeline under the window's settings.

#include "detect/earliest.hpp"

#include <fmt/format.h>

#include <bit>
#include <cmath>

#include "clothcd/core/error.hpp"
#include "detect/self_core.hpp"

namespace clothcd::detail {

void check_earliest_options(const EarliestOptions& o) {
  if (!(o.toi_tolerance > 0) || !std::isfinite(o.toi_tolerance)) {
    throw InputError(fmt::format("earliest_impact: toi_tolerance must be finite and > 0, got {}",
                                 o.toi_tolerance));
  }
  if (o.first_window != 0) {
    int e = 0;
    const double m = std::frexp(o.first_window, &e);
    if (!(o.first_window > 0 && o.first_window <= 1) || m != 0.5) {
      throw InputError(fmt::format(
          "earliest_impact: first_window must be 0 (automatic) or a power of two in (0, 1], got "
          "{}",
          o.first_window));
    }
  }
}

double first_window(const EarliestOptions& options, std::span<const Topology* const> meshes,
                    std::span<const std::span<const Eigen::Vector3d>> x0,
                    std::span<const std::span<const Eigen::Vector3d>> x1) {
  if (options.first_window != 0) return options.first_window;
  double edges = 0, count = 0, moved = 0;
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    for (const Edge& e : meshes[m]->edges())
      edges += (x0[m][e[0]] - x0[m][e[1]]).norm();
    count += static_cast<double>(meshes[m]->edges().size());
    for (std::size_t i = 0; i < x0[m].size(); ++i)
      moved = std::max(moved, (x1[m][i] - x0[m][i]).norm());
  }
  if (count == 0 || moved == 0) return 1.0;
  const double reach = edges / count / kFirstWindowShare;
  double t = 1.0;
  while (t > 0x1p-30 && t * moved > reach)
    t *= 0.5;
  return t;
}

void add_stats(const DetectStats& w, DetectStats& s) {
  s.box_tests += w.box_tests;
  s.nodes_culled += w.nodes_culled;
  s.cone_tests += w.cone_tests;
  s.contour_tests += w.contour_tests;
  s.contour_fails += w.contour_fails;
  s.internal_nodes = w.internal_nodes;
  s.connected_internal_nodes = w.connected_internal_nodes;
  s.disk_internal_nodes = w.disk_internal_nodes;
  s.adjacent_pairs += w.adjacent_pairs;
  s.triangle_pairs += w.triangle_pairs;
  s.triangle_pairs_apart += w.triangle_pairs_apart;
  s.vf_tests += w.vf_tests;
  s.ee_tests += w.ee_tests;
  s.vf_np_culled += w.vf_np_culled;
  s.ee_np_culled += w.ee_np_culled;
  s.vf_orphans += w.vf_orphans;
  s.ee_orphans += w.ee_orphans;
  s.vf_collisions += w.vf_collisions;
  s.ee_collisions += w.ee_collisions;
  s.time_refit += w.time_refit;
  s.time_traverse += w.time_traverse;
  s.time_narrow += w.time_narrow;
}

EarliestImpact SelfCore::earliest_impact(PointsIn p0, PointsIn p1, const EarliestOptions& eo) {
  check_earliest_options(eo);
  const int nv = topo.num_vertices();
  std::vector<Eigen::Vector3d> x0, x1, xs, xt;
  to_points(p0, nv, "positions at t0", x0);
  to_points(p1, nv, "positions at t1", x1);
  update_links();
  const Topology* const mesh[] = {&topo};
  const std::span<const Eigen::Vector3d> s0[] = {x0}, s1[] = {x1};
  const double first = first_window(eo, mesh, s0, s1);
  const auto& faces = topo.faces();
  const auto& edges = topo.edges();
  const auto make_vf = [&](int v, int f, bool) {
    const Face& t = faces[f];
    return VertexFaceQuery{x0[v], x0[t[0]], x0[t[1]], x0[t[2]],
                           x1[v], x1[t[0]], x1[t[1]], x1[t[2]]};
  };
  const auto make_ee = [&](int i, int j) {
    const Edge &a = edges[i], &b = edges[j];
    return EdgeEdgeQuery{x0[a[0]], x0[a[1]], x0[b[0]], x0[b[1]],
                         x1[a[0]], x1[a[1]], x1[b[0]], x1[b[1]]};
  };
  EarliestSearch search(ccd_context().ccd, eo.toi_tolerance, make_vf, make_ee);
  // A window's settings (window_options) replace the detector's for its detection only.
  const DetectOptions saved = opt;
  const Rule saved_rule = cull;
  struct Restore {
    SelfCore& core;
    const DetectOptions& saved;
    Rule rule;
    ~Restore() {
      core.opt = saved;
      core.cull = rule;
    }
  } restore{*this, saved, saved_rule};
  return search_windows(first, rounding_slack(x0, x1), search,
                        [&](double lo, double hi, double slack, DetectStats& stats) {
                          const bool whole = lo == 0 && hi == 1;
                          opt = window_options(saved, slack, search.kernel().toi_tolerance);
                          // A short window's boxes are small: cones would cost a refit of their own
                          // and cull little, so its traversal tests boxes only. Its filters pick
                          // its hits, which the step's kernels time; the whole step's hits come
                          // with their coarse times.
                          cull = whole ? saved_rule : Rule::None;
                          if (lo > 0) interpolate(x0, x1, lo, xs);
                          if (hi < 1) interpolate(x0, x1, hi, xt);
                          const DetectResult r =
                              detect(std::span<const Eigen::Vector3d>(lo > 0 ? xs : x0),
                                     std::span<const Eigen::Vector3d>(hi < 1 ? xt : x1), whole);
                          add_stats(r.stats, stats);
                          search.add(r.vf, r.ee, false);
                        });
}

}  // namespace clothcd::detail
