#pragma once
// The continuous contour test of algorithms.md 1.5: the oriented boundary loop of a disk node,
// projected along the cone axis, stays star-shaped about its moving centroid over the whole step.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <span>

namespace clothcd::detail {

/// True when every s_i(t) = det[p_i - o, p_{i+1} - o, axis] has all three Bernstein coefficients
/// above a rounding margin and the loop winds once around o at t = 0. `axis` is unit.
inline bool contour_star_shaped(std::span<const int> loop, std::span<const Eigen::Vector3d> v0,
                                std::span<const Eigen::Vector3d> v1, const Eigen::Vector3d& axis) {
  const std::size_t n = loop.size();
  if (n < 3) return false;
  Eigen::Vector3d o0 = Eigen::Vector3d::Zero(), o1 = Eigen::Vector3d::Zero();
  for (int v : loop) {
    o0 += v0[v];
    o1 += v1[v];
  }
  // Any linearly moving reference point works; the mean of the loop is a good one.
  o0 /= double(n);
  o1 /= double(n);
  constexpr double kRel = 1e-12;  // far above the few-ulp error of these short expressions
  double winding = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const int p = loop[i], q = loop[(i + 1) % n];
    const Eigen::Vector3d x0 = v0[p] - o0, y0 = v0[q] - o0;
    const Eigen::Vector3d x1 = v1[p] - o1, y1 = v1[q] - o1;
    const double s0 = x0.cross(y0).dot(axis);
    const double s1 = x1.cross(y1).dot(axis);
    const double sm = 0.5 * (x0.cross(y1) + x1.cross(y0)).dot(axis);
    const double nx0 = x0.norm(), ny0 = y0.norm(), nx1 = x1.norm(), ny1 = y1.norm();
    const double eta = kRel * (nx0 * ny0 + nx0 * ny1 + nx1 * ny0 + nx1 * ny1);
    if (!(s0 > eta && sm > eta && s1 > eta)) return false;
    // Signed angle of the edge seen from o in the plane orthogonal to the axis, in (0, pi).
    const double dot = x0.dot(y0) - x0.dot(axis) * y0.dot(axis);
    winding += std::atan2(s0, dot);
  }
  // Each term is in (0, pi), so the sum is 2 pi times an integer winding number up to rounding.
  return std::abs(winding - 2 * std::numbers::pi) < std::numbers::pi;
}

}  // namespace clothcd::detail
