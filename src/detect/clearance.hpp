#pragma once
// Clearances for sound cone culling with a contact distance R > 0 (docs/algorithms.md 1.6): a
// lower bound, over the whole step, on how close a patch's features can come to the features they
// do not touch. Every bound is a distance at t = 0 and at t = 1 and a Lipschitz constant of the
// relative motion: a distance that is d0 at t = 0, d1 at t = 1 and changes at most at rate L is
// at least (d0 + d1 - L) / 2 throughout.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "contour.hpp"

namespace clothcd::detail {

// Relative rounding allowance of the short distance expressions below (a few ulps of the
// coordinates, far below this).
inline constexpr double kClearanceRounding = 1e-12;

/// Distance from p to the segment [a, b], in any dimension.
template <class Vec>
[[nodiscard]] double point_segment_distance(const Vec& p, const Vec& a, const Vec& b) {
  const Vec ab = b - a;
  const double len2 = ab.squaredNorm();
  double s = len2 > 0 ? (p - a).dot(ab) / len2 : 0.0;
  s = std::clamp(s, 0.0, 1.0);
  return (p - (a + s * ab)).norm();
}

/// Lower bound over the step of the distance from a linearly moving point p to a linearly moving
/// segment [a, b]. Seen from p the segment's ends move linearly by da - dp and db - dp, and the
/// distance from a fixed point to a segment changes by at most the larger end displacement, so
/// only the relative motion counts (a patch moving rigidly keeps its clearances).
template <class Vec>
[[nodiscard]] double moving_point_segment_clearance(const Vec& p0, const Vec& p1, const Vec& a0,
                                                    const Vec& a1, const Vec& b0, const Vec& b1) {
  const double d0 = point_segment_distance(p0, a0, b0);
  const double d1 = point_segment_distance(p1, a1, b1);
  const Vec dp = p1 - p0;
  const double rate = std::max((a1 - a0 - dp).norm(), (b1 - b0 - dp).norm());
  return 0.5 * (d0 + d1 - rate);
}

/// The smallest clearance of a corner of triangle (a, b, c) over the step: the distance from each
/// vertex to the opposite edge, in 3-D, with the rounding allowance taken off.
[[nodiscard]] inline double triangle_corner_clearance(
    const std::array<const Eigen::Vector3d*, 3>& x0,
    const std::array<const Eigen::Vector3d*, 3>& x1) {
  double clearance = std::numeric_limits<double>::infinity();
  double scale = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    clearance = std::min(
        clearance, moving_point_segment_clearance(*x0[i], *x1[i], *x0[j], *x1[j], *x0[k], *x1[k]));
    scale = std::max({scale, x0[i]->lpNorm<Eigen::Infinity>(), x1[i]->lpNorm<Eigen::Infinity>()});
  }
  return clearance - kClearanceRounding * scale;
}

/// A triangle's smallest height: twice its area over its longest side (NaN with no extent).
[[nodiscard]] inline double triangle_smallest_height(
    const std::array<const Eigen::Vector3d*, 3>& x) {
  const Eigen::Vector3d ab = *x[1] - *x[0], ac = *x[2] - *x[0], bc = *x[2] - *x[1];
  const double longest2 = std::max({ab.squaredNorm(), ac.squaredNorm(), bc.squaredNorm()});
  return ab.cross(ac).norm() / std::sqrt(longest2);
}

/// A lower bound on triangle_corner_clearance(x0, x1), below it by at least its rounding, in
/// fewer operations: every corner's distance to its opposite side is at least the triangle's
/// smallest height (twice its area over its longest side) at each end of the step, and every
/// corner moves against its side at most as fast as the fastest relative motion of two
/// corners. Twice the rounding allowance taken off covers the rounding of both expressions.
/// NaN for a triangle with no extent (then use the exact clearance).
[[nodiscard]] inline double triangle_corner_clearance_bound(
    const std::array<const Eigen::Vector3d*, 3>& x0,
    const std::array<const Eigen::Vector3d*, 3>& x1) {
  double rate2 = 0, scale = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    rate2 = std::max(rate2, ((*x1[j] - *x0[j]) - (*x1[i] - *x0[i])).squaredNorm());
    scale = std::max({scale, x0[i]->lpNorm<Eigen::Infinity>(), x1[i]->lpNorm<Eigen::Infinity>()});
  }
  return 0.5 * (triangle_smallest_height(x0) + triangle_smallest_height(x1) - std::sqrt(rate2)) -
         2 * kClearanceRounding * scale;
}

/// triangle_corner_clearance_bound(x0, x1) and the same bound for the step's end alone,
/// triangle_corner_clearance_bound(x1, x1), from one pass over the corners.
struct CornerBounds {
  double step, end;
};
[[nodiscard]] inline CornerBounds triangle_corner_clearance_bounds(
    const std::array<const Eigen::Vector3d*, 3>& x0,
    const std::array<const Eigen::Vector3d*, 3>& x1) {
  double rate2 = 0, scale = 0, scale1 = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    rate2 = std::max(rate2, ((*x1[j] - *x0[j]) - (*x1[i] - *x0[i])).squaredNorm());
    const double s1 = x1[i]->lpNorm<Eigen::Infinity>();
    scale = std::max({scale, x0[i]->lpNorm<Eigen::Infinity>(), s1});
    scale1 = std::max(scale1, s1);
  }
  const double h1 = triangle_smallest_height(x1);
  return {
      0.5 * (triangle_smallest_height(x0) + h1 - std::sqrt(rate2)) - 2 * kClearanceRounding * scale,
      h1 - 2 * kClearanceRounding * scale1};  // 0.5 * (h1 + h1 - 0), exactly
}

/// True when, projected along the unit `axis`, every vertex of the contour loop stays farther than
/// `reach` from every loop edge that does not end at it, over the whole step. Pairs of edges whose
/// swept 2-D boxes, grown by `reach`, do not overlap are apart by more than `reach` throughout;
/// the others are bounded as moving segments (for segments that do not cross, the distance is the
/// smallest of the four endpoint-to-segment distances; the caller has shown they never cross).
[[nodiscard]] inline bool contour_clear(std::span<const int> loop,
                                        std::span<const Eigen::Vector3d> v0,
                                        std::span<const Eigen::Vector3d> v1,
                                        const Eigen::Vector3d& axis, double reach) {
  const int n = static_cast<int>(loop.size());
  if (n < 3) return false;
  const Eigen::Vector3d u = axis.unitOrthogonal();
  const Eigen::Vector3d w = axis.cross(u);
  // Scratch buffers a thread (contour_simple's are its own: no call of one runs inside the other).
  thread_local std::vector<Eigen::Vector2d> p0, p1;
  p0.resize(n);
  p1.resize(n);
  double scale = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d &x0 = v0[loop[i]], &x1 = v1[loop[i]];
    p0[i] = {x0.dot(u), x0.dot(w)};
    p1[i] = {x1.dot(u), x1.dot(w)};
    scale = std::max({scale, x0.lpNorm<Eigen::Infinity>(), x1.lpNorm<Eigen::Infinity>()});
  }
  const double need = reach + kClearanceRounding * scale;
  auto clear = [&](int p, int a, int b) {
    return moving_point_segment_clearance(p0[p], p1[p], p0[a], p1[a], p0[b], p1[b]) > need;
  };
  // A vertex against the edge after next and the edge before last (the two edges that share an
  // end with one of its own edges).
  for (int i = 0; i < n; ++i) {
    const int a = (i + n - 1) % n, c = (i + 1) % n;
    if (!clear(a, i, c) || !clear(c, a, i)) return false;
  }
  return for_each_near_edge_pair(p0, p1, need, [&](int i, int j) {
    const int i2 = (i + 1) % n, j2 = (j + 1) % n;
    return clear(i, j, j2) && clear(i2, j, j2) && clear(j, i, i2) && clear(j2, i, i2);
  });
}

}  // namespace clothcd::detail
