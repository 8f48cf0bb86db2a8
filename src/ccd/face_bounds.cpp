// Distance bounds of whole triangles (face_bounds.hpp).
#include "ccd/face_bounds.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "slack.hpp"

namespace clothcd::detail {
namespace {

using Vec3 = Eigen::Vector3d;

// How far b lies wholly on one side of a's plane (0 where it straddles it). The normal is trusted
// as in the feature bounds (proximity.cpp): only where the sine of a's angle at a[0] exceeds 1e-3.
double plane_separation(const Triangle& a, const Triangle& b) {
  const Vec3 u = *a[1] - *a[0], v = *a[2] - *a[0];
  const Vec3 w = u.cross(v);
  const double w2 = w.squaredNorm();
  if (!(w2 > 1e-6 * u.squaredNorm() * v.squaredNorm())) return 0.0;
  double lo = INFINITY, hi = -INFINITY;
  for (const Vec3* p : b) {
    const double s = w.dot(*p - *a[0]);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  const double side = lo > 0.0 ? lo : (hi < 0.0 ? -hi : 0.0);
  return side / std::sqrt(w2);
}

double box_gap(const Triangle& a, const Triangle& b) {
  Vec3 lo_a = *a[0], hi_a = *a[0], lo_b = *b[0], hi_b = *b[0];
  for (int k = 1; k < 3; ++k) {
    lo_a = lo_a.cwiseMin(*a[k]);
    hi_a = hi_a.cwiseMax(*a[k]);
    lo_b = lo_b.cwiseMin(*b[k]);
    hi_b = hi_b.cwiseMax(*b[k]);
  }
  return (lo_b - hi_a).cwiseMax(lo_a - hi_b).cwiseMax(0.0).norm();
}

double slack(const Triangle& a, const Triangle& b) {
  return coordinate_slack({a[0], a[1], a[2], b[0], b[1], b[2]});
}

// triangle_triangle_bound given the two triangles' slack.
double bound_less(const Triangle& a, const Triangle& b, double slack) {
  const double bound = std::max({box_gap(a, b), plane_separation(a, b), plane_separation(b, a)});
  return std::max(0.0, bound - slack);
}

}  // namespace

double triangle_triangle_bound(const Triangle& a, const Triangle& b) {
  return bound_less(a, b, slack(a, b));
}

bool triangles_filter_culls(const Triangle& a_t0, const Triangle& a_t1, const Triangle& b_t0,
                            const Triangle& b_t1, double thickness, double* bound_t1) {
  double move2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    const Vec3 da = *a_t1[i] - *a_t0[i];
    for (int j = 0; j < 3; ++j)
      move2 = std::max(move2, (da - (*b_t1[j] - *b_t0[j])).squaredNorm());
  }
  // The same test as the distance filter's whole-step bound, with the largest slack of any of
  // the feature pairs (theirs are taken over fewer points).
  const double s0 = slack(a_t0, b_t0), s1 = slack(a_t1, b_t1);
  const double eps = std::max(s0, s1);
  const double d1 = bound_less(a_t1, b_t1, s1);
  if (bound_t1 != nullptr) *bound_t1 = d1;
  const double bound = 0.5 * (bound_less(a_t0, b_t0, s0) + d1 - std::sqrt(move2));
  return std::isfinite(bound) && bound > thickness + eps;
}

}  // namespace clothcd::detail
