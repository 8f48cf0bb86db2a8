// The binary merges of normal cones (docs/algorithms.md 3.1 and 3.2) and cone containment.
#include "clothcd/geometry/cone.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "clothcd/geometry/angle.hpp"
#include "sphere_caps.hpp"
#include "validate.hpp"

namespace clothcd {

namespace {

// Below this |a1 x a2| the great circle through the axes is not resolvable (its direction
// would underflow); any axis between them then works with the safe angle max(t1, t2) + beta.
constexpr double kParallelSine = 1e-140;

// A merge input, checked and with a unit axis. `degenerate` marks a zero axis.
struct CheckedCone {
  Eigen::Vector3d axis;
  double half_angle;
  bool degenerate;
};

CheckedCone checked(const NormalCone& cone, const char* function, const char* which) {
  detail::require_finite(cone.axis, function, which);
  detail::require_finite_angle(cone.half_angle, function, which);
  const double n2 = cone.axis.squaredNorm();
  if (!(n2 > 1e-280)) return {Eigen::Vector3d::UnitZ(), kSaturatedHalfAngle, true};
  // Callers pass unit axes; renormalize only when they visibly are not.
  const Eigen::Vector3d axis = std::abs(n2 - 1.0) > 1e-14 ? cone.axis / std::sqrt(n2) : cone.axis;
  return {axis, cone.half_angle, false};
}

bool saturates(const CheckedCone& c) {
  return c.degenerate || !(c.half_angle < kSaturatedHalfAngle);
}

// A finished merge: slack added, saturated results clamped to the canonical form.
NormalCone finish(const Eigen::Vector3d& axis, double theta) {
  theta += kConeSlack;
  if (!(theta < kSaturatedHalfAngle)) return saturated_cone(axis);
  return {axis, theta};
}

// The point at angle alpha from a1 toward a2 on their great circle (Slerp by alpha / beta).
Eigen::Vector3d along_great_circle(const Eigen::Vector3d& a1, const Eigen::Vector3d& a1xa2,
                                   double alpha) {
  // w = (a1 x a2) x a1 / |.| is the unit tangent at a1 toward a2: the same as
  // normalize(a2 - (a1.a2) a1) but unaffected by |a2| != 1 in the last bit.
  const Eigen::Vector3d w = a1xa2.cross(a1).normalized();
  return detail::rotate_toward(a1, w, alpha);
}

}  // namespace

bool NormalCone::saturated() const {
  return !(half_angle < std::numbers::pi / 2);
}

NormalCone merge_provot(const NormalCone& a, const NormalCone& b) {
  const CheckedCone c1 = checked(a, "merge_provot", "first cone");
  const CheckedCone c2 = checked(b, "merge_provot", "second cone");
  if (saturates(c1) || saturates(c2)) return saturated_cone(c1.degenerate ? c2.axis : c1.axis);
  const Eigen::Vector3d cross = precise_cross(c1.axis, c2.axis);
  const double sine = cross.norm();
  const double beta = std::atan2(sine, c1.axis.dot(c2.axis));
  const double theta = 0.5 * beta + std::max(c1.half_angle, c2.half_angle);
  if (!(theta + kConeSlack < kSaturatedHalfAngle)) return saturated_cone(c1.axis);
  // normalize(a1 + a2) is the Slerp midpoint; computing it as a rotation by beta/2 keeps it
  // accurate when the axes are nearly antiparallel (a1 + a2 cancels).
  if (sine < kParallelSine) return finish((c1.axis + c2.axis).normalized(), theta);
  return finish(along_great_circle(c1.axis, cross, 0.5 * beta), theta);
}

NormalCone merge_tight(const NormalCone& a, const NormalCone& b) {
  const CheckedCone c1 = checked(a, "merge_tight", "first cone");
  const CheckedCone c2 = checked(b, "merge_tight", "second cone");
  // 1. Saturate first: the span formulas do not hold beyond pi/2 (erratum 2).
  if (saturates(c1) || saturates(c2)) return saturated_cone(c1.degenerate ? c2.axis : c1.axis);
  const double t1 = c1.half_angle;
  const double t2 = c2.half_angle;
  const Eigen::Vector3d cross = precise_cross(c1.axis, c2.axis);
  const double sine = cross.norm();
  const double beta = std::atan2(sine, c1.axis.dot(c2.axis));
  // 2. Inclusive cases: one cone already holds the other.
  if (beta + t2 <= t1) return finish(c1.axis, t1);
  if (beta + t1 <= t2) return finish(c2.axis, t2);
  // 3. The interval hull [-t1, beta + t2] in the a1-polar frame; saturate before any axis.
  const double theta = 0.5 * (beta + t1 + t2);
  if (!(theta + kConeSlack < kSaturatedHalfAngle)) return saturated_cone(c1.axis);
  // 4. Its midpoint alpha in (0, beta), measured from a1 toward a2.
  if (sine < kParallelSine) {
    return finish((c1.axis + c2.axis).normalized(), std::max(t1, t2) + beta);
  }
  const double alpha = 0.5 * (beta + t2 - t1);
  return finish(along_great_circle(c1.axis, cross, alpha), theta);
}

bool contains(const NormalCone& cone, const Eigen::Vector3d& dir) {
  detail::require_finite(cone.axis, "contains", "cone axis");
  detail::require_finite(dir, "contains", "direction");
  if (cone.saturated()) return true;
  if (dir.isZero(0.0) || cone.axis.isZero(0.0)) return false;
  return angle_between(cone.axis, dir) <= cone.half_angle;
}

bool contains(const NormalCone& outer, const NormalCone& inner, double slack) {
  detail::require_finite(outer.axis, "contains", "outer cone axis");
  detail::require_finite(inner.axis, "contains", "inner cone axis");
  if (outer.saturated()) return true;
  if (inner.saturated() || outer.axis.isZero(0.0) || inner.axis.isZero(0.0)) return false;
  return angle_between(outer.axis, inner.axis) + inner.half_angle <= outer.half_angle + slack;
}

}  // namespace clothcd
