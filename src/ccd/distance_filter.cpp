// Distance filter: a lower bound on the features' distance over a linear motion.
#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "clothcd/ccd/proximity.hpp"
#include "clothcd/ccd/queries.hpp"

namespace clothcd {
namespace {

using Vec3 = Eigen::Vector3d;

// Rounding slack of the two distance evaluations: far above their error (a few ulps of the
// coordinates), far below any thickness a simulator uses.
double slack(std::initializer_list<const Vec3*> pts) {
  double m = 1.0;
  for (const Vec3* p : pts)
    m = std::max(m, p->cwiseAbs().maxCoeff());
  return 1e-12 * m;
}

double largest_relative_move(std::initializer_list<Vec3> a, std::initializer_list<Vec3> b) {
  double d = 0.0;
  for (const Vec3& x : a) {
    for (const Vec3& y : b)
      d = std::max(d, (x - y).squaredNorm());
  }
  return std::sqrt(d);
}

bool culls(double d0, double d1, double move, double thickness, double eps) {
  const double bound = 0.5 * (d0 + d1 - move);
  return std::isfinite(bound) && bound > thickness + eps;
}

// The bound on [ta, tb] (distances da, db at its ends), bisected up to `depth` times where it
// fails: the distance is Lipschitz with constant `move` on any part of the step, so each half
// needs only its own end distances. `dist(t)` is the distance at time t.
template <class Dist>
bool culls_on(double ta, double tb, double da, double db, double move, double thickness, double eps,
              int depth, Dist&& dist) {
  if (culls(da, db, move * (tb - ta), thickness, eps)) return true;
  if (depth <= 0 || !(std::min(da, db) > thickness + eps)) return false;
  const double tm = 0.5 * (ta + tb);
  const double dm = dist(tm);
  return culls_on(ta, tm, da, dm, move, thickness, eps, depth - 1, dist) &&
         culls_on(tm, tb, dm, db, move, thickness, eps, depth - 1, dist);
}

Vec3 at(const Vec3& x0, const Vec3& x1, double t) {
  return x0 + t * (x1 - x0);
}

}  // namespace

bool distance_filter_culls(const VertexFaceQuery& q, double thickness, int depth) {
  const double move = largest_relative_move(
      {q.v_t1 - q.v_t0}, {q.f0_t1 - q.f0_t0, q.f1_t1 - q.f1_t0, q.f2_t1 - q.f2_t0});
  const double eps =
      slack({&q.v_t0, &q.f0_t0, &q.f1_t0, &q.f2_t0, &q.v_t1, &q.f0_t1, &q.f1_t1, &q.f2_t1});
  // Lower bounds first: where they cull, the distances would too (the bound grows with them).
  if (culls(point_triangle_distance_lower_bound(q.v_t0, q.f0_t0, q.f1_t0, q.f2_t0),
            point_triangle_distance_lower_bound(q.v_t1, q.f0_t1, q.f1_t1, q.f2_t1), move, thickness,
            eps)) {
    return true;
  }
  const double d0 = point_triangle_proximity(q.v_t0, q.f0_t0, q.f1_t0, q.f2_t0).distance;
  const double d1 = point_triangle_proximity(q.v_t1, q.f0_t1, q.f1_t1, q.f2_t1).distance;
  return culls_on(0.0, 1.0, d0, d1, move, thickness, eps, depth, [&](double t) {
    return point_triangle_proximity(at(q.v_t0, q.v_t1, t), at(q.f0_t0, q.f0_t1, t),
                                    at(q.f1_t0, q.f1_t1, t), at(q.f2_t0, q.f2_t1, t))
        .distance;
  });
}

bool distance_filter_culls(const EdgeEdgeQuery& q, double thickness, int depth) {
  const double move = largest_relative_move({q.ea0_t1 - q.ea0_t0, q.ea1_t1 - q.ea1_t0},
                                            {q.eb0_t1 - q.eb0_t0, q.eb1_t1 - q.eb1_t0});
  const double eps = slack(
      {&q.ea0_t0, &q.ea1_t0, &q.eb0_t0, &q.eb1_t0, &q.ea0_t1, &q.ea1_t1, &q.eb0_t1, &q.eb1_t1});
  if (culls(edge_edge_distance_lower_bound(q.ea0_t0, q.ea1_t0, q.eb0_t0, q.eb1_t0),
            edge_edge_distance_lower_bound(q.ea0_t1, q.ea1_t1, q.eb0_t1, q.eb1_t1), move, thickness,
            eps)) {
    return true;
  }
  const double d0 = edge_edge_proximity(q.ea0_t0, q.ea1_t0, q.eb0_t0, q.eb1_t0).distance;
  const double d1 = edge_edge_proximity(q.ea0_t1, q.ea1_t1, q.eb0_t1, q.eb1_t1).distance;
  return culls_on(0.0, 1.0, d0, d1, move, thickness, eps, depth, [&](double t) {
    return edge_edge_proximity(at(q.ea0_t0, q.ea0_t1, t), at(q.ea1_t0, q.ea1_t1, t),
                               at(q.eb0_t0, q.eb0_t1, t), at(q.eb1_t0, q.eb1_t1, t))
        .distance;
  });
}

}  // namespace clothcd
