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

}  // namespace

bool distance_filter_culls(const VertexFaceQuery& q, double thickness) {
  const double d0 = point_triangle_proximity(q.v_t0, q.f0_t0, q.f1_t0, q.f2_t0).distance;
  const double d1 = point_triangle_proximity(q.v_t1, q.f0_t1, q.f1_t1, q.f2_t1).distance;
  const double move = largest_relative_move(
      {q.v_t1 - q.v_t0}, {q.f0_t1 - q.f0_t0, q.f1_t1 - q.f1_t0, q.f2_t1 - q.f2_t0});
  return culls(
      d0, d1, move, thickness,
      slack({&q.v_t0, &q.f0_t0, &q.f1_t0, &q.f2_t0, &q.v_t1, &q.f0_t1, &q.f1_t1, &q.f2_t1}));
}

bool distance_filter_culls(const EdgeEdgeQuery& q, double thickness) {
  const double d0 = edge_edge_proximity(q.ea0_t0, q.ea1_t0, q.eb0_t0, q.eb1_t0).distance;
  const double d1 = edge_edge_proximity(q.ea0_t1, q.ea1_t1, q.eb0_t1, q.eb1_t1).distance;
  const double move = largest_relative_move({q.ea0_t1 - q.ea0_t0, q.ea1_t1 - q.ea1_t0},
                                            {q.eb0_t1 - q.eb0_t0, q.eb1_t1 - q.eb1_t0});
  return culls(d0, d1, move, thickness,
               slack({&q.ea0_t0, &q.ea1_t0, &q.eb0_t0, &q.eb1_t0, &q.ea0_t1, &q.ea1_t1, &q.eb0_t1,
                      &q.eb1_t1}));
}

}  // namespace clothcd
