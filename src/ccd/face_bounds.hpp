#pragma once
// Bounds on the distance between two whole triangles, for a narrow phase that would otherwise
// bound each of a triangle pair's feature pairs (6 VF, 9 EE) on its own. Unchecked: every point
// must be finite.

#include <Eigen/Core>

#include <array>
#include <span>

namespace clothcd::ccd_detail {

using Triangle = std::array<const Eigen::Vector3d*, 3>;

/// The corners of face f (vertex ids) in positions x.
inline Triangle corners(std::span<const Eigen::Vector3d> x, const std::array<int, 3>& f) {
  return {&x[f[0]], &x[f[1]], &x[f[2]]};
}

/// Lower bound on the distance between triangles a and b, less the rounding allowance of
/// slack.hpp: the larger of their boxes' gap and the separation by either triangle's plane (how
/// far the other triangle lies wholly on one side of it; 0 where it does not, or where the
/// triangle is too thin for its normal to be trusted). No feature pair of the two triangles is
/// closer.
[[nodiscard]] double triangle_triangle_bound(const Triangle& a, const Triangle& b);

/// Whether distance_filter_culls (without bisection) culls every feature pair of triangles a and
/// b moving linearly from *_t0 to *_t1: the whole-step bound (d0 + d1 - D) / 2 with the triangles'
/// bound at both ends and D the largest relative displacement of a vertex of a against one of b.
/// Each feature pair's own distances are at least these bounds and its own D at most this D, so
/// where this culls, each of them culls as well.
/// `bound_t1`, when given, receives triangle_triangle_bound(a_t1, b_t1), computed on the way.
[[nodiscard]] bool triangles_filter_culls(const Triangle& a_t0, const Triangle& a_t1,
                                          const Triangle& b_t0, const Triangle& b_t1,
                                          double thickness, double* bound_t1 = nullptr);

}  // namespace clothcd::ccd_detail
