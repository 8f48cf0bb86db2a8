#pragma once
// The continuous contour test of docs/algorithms.md 1.5: the oriented boundary loop of a disk node,
// projected along the cone axis, stays star-shaped about its moving centroid over the whole step.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <vector>

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

/// Bernstein coefficients of (x(t) x y(t)) . axis for x, y moving linearly over [0, 1], and the
/// rounding margin of that expression: the quadratic is nonzero on [0, 1] when all three
/// coefficients exceed the margin in absolute value with one sign.
struct Quadratic {
  std::array<double, 3> c;
  double eta;
  [[nodiscard]] int sign() const {
    if (c[0] > eta && c[1] > eta && c[2] > eta) return 1;
    if (c[0] < -eta && c[1] < -eta && c[2] < -eta) return -1;
    return 0;
  }
};

inline Quadratic det_quadratic(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                               const Eigen::Vector3d& y0, const Eigen::Vector3d& y1,
                               const Eigen::Vector3d& axis) {
  constexpr double kRel = 1e-12;
  const double nx0 = x0.norm(), ny0 = y0.norm(), nx1 = x1.norm(), ny1 = y1.norm();
  return {{x0.cross(y0).dot(axis), 0.5 * (x0.cross(y1) + x1.cross(y0)).dot(axis),
           x1.cross(y1).dot(axis)},
          kRel * (nx0 * ny0 + nx0 * ny1 + nx1 * ny0 + nx1 * ny1)};
}

/// Calls pair(i, j) for every two non-consecutive edges of a closed loop (edge i runs from
/// position i to i + 1) whose swept 2-D boxes, grown by `margin`, overlap, and returns false as
/// soon as a call does. p0, p1: the loop's projected positions at t = 0 and t = 1; the hull of an
/// edge's positions over [0, 1] lies in the box of its four endpoint positions.
template <class Pair>
bool for_each_near_edge_pair(std::span<const Eigen::Vector2d> p0,
                             std::span<const Eigen::Vector2d> p1, double margin, Pair&& pair) {
  const int n = static_cast<int>(p0.size());
  struct Box {
    Eigen::Vector2d lo, hi;
    int edge;
  };
  // One scratch buffer a thread: no allocation once it has grown (the traversal tests many
  // contours a call).
  thread_local std::vector<Box> scratch;
  std::vector<Box>& boxes = scratch;
  boxes.resize(n);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    Box& b = boxes[i];
    b.lo = p0[i].cwiseMin(p1[i]).cwiseMin(p0[j]).cwiseMin(p1[j]).array() - margin;
    b.hi = p0[i].cwiseMax(p1[i]).cwiseMax(p0[j]).cwiseMax(p1[j]).array() + margin;
    b.edge = i;
  }
  std::sort(boxes.begin(), boxes.end(), [](const Box& x, const Box& y) {
    return x.lo[0] < y.lo[0] || (x.lo[0] == y.lo[0] && x.edge < y.edge);
  });
  for (int k = 0; k < n; ++k) {
    const Box& bi = boxes[k];
    for (int m = k + 1; m < n && boxes[m].lo[0] <= bi.hi[0]; ++m) {
      const Box& bj = boxes[m];
      if (bj.lo[1] > bi.hi[1] || bi.lo[1] > bj.hi[1]) continue;
      const int i = bi.edge, j = bj.edge;
      if ((i + 1) % n == j || (j + 1) % n == i) continue;  // consecutive: the caller's own check
      if (!pair(i, j)) return false;
    }
  }
  return true;
}

/// The general contour test (docs/algorithms.md 1.5): the loop, projected along the unit
/// `axis`, is a simple closed curve with positive area for every t in [0, 1]. With a cone below
/// pi/2 every projected triangle is positively oriented, so the number of preimages of a point is
/// the loop's winding number about it (0 or 1): the projection is injective and the patch cannot
/// touch itself. Sufficient conditions checked, all conservative:
/// - consecutive edges never fold onto each other: their cross product stays nonzero, or their
///   dot product stays negative (Bernstein coefficients past a margin);
/// - two non-consecutive edges whose swept 2-D boxes overlap never meet: each endpoint's
///   orientation against the other edge's line keeps a sign over [0, 1], and at t = 0 the signs
///   say the segments are apart (so they are apart throughout);
/// - the loop's signed area at t = 0 is positive (a simple curve keeps its orientation).
/// Quadratic in the worst case, but pruned by a sweep over the boxes; used where the cheaper
/// star-shaped test fails (jagged patch boundaries are rarely star-shaped about their mean).
inline bool contour_simple(std::span<const int> loop, std::span<const Eigen::Vector3d> v0,
                           std::span<const Eigen::Vector3d> v1, const Eigen::Vector3d& axis) {
  const int n = static_cast<int>(loop.size());
  if (n < 3) return false;
  // Projected coordinates in a basis (u, w) of the plane orthogonal to the axis.
  const Eigen::Vector3d u = axis.unitOrthogonal();
  const Eigen::Vector3d w = axis.cross(u);
  auto proj = [&](const Eigen::Vector3d& x) { return Eigen::Vector2d(x.dot(u), x.dot(w)); };
  auto perp = [&](const Eigen::Vector3d& x) { return x - x.dot(axis) * axis; };

  // Consecutive edges (a -> b, b -> c): no fold at b.
  double area = 0, extent = 0, scale = 0;
  for (int i = 0; i < n; ++i) {
    const int a = loop[(i + n - 1) % n], b = loop[i], c = loop[(i + 1) % n];
    const Eigen::Vector3d x0 = v0[a] - v0[b], x1 = v1[a] - v1[b];
    const Eigen::Vector3d y0 = v0[c] - v0[b], y1 = v1[c] - v1[b];
    if (det_quadratic(x0, x1, y0, y1, axis).sign() == 0) {
      const Eigen::Vector3d px0 = perp(x0), px1 = perp(x1), py0 = perp(y0), py1 = perp(y1);
      const double eta = 1e-12 * (x0.norm() + x1.norm()) * (y0.norm() + y1.norm());
      const double d0 = px0.dot(py0), d1 = 0.5 * (px0.dot(py1) + px1.dot(py0)), d2 = px1.dot(py1);
      if (!(d0 < -eta && d1 < -eta && d2 < -eta)) return false;
    }
    // Shoelace about the first loop vertex, so the rounding scales with the patch, not with its
    // distance from the origin.
    const Eigen::Vector3d o = v0[loop[0]];
    area += (v0[b] - o).cross(v0[c] - o).dot(axis);
    extent = std::max(extent, (v0[b] - o).norm());
    scale = std::max({scale, v0[b].norm(), v1[b].norm()});
  }
  if (!(area > 1e-12 * n * extent * extent)) return false;

  thread_local std::vector<Eigen::Vector2d> p0, p1;  // scratch, as in for_each_near_edge_pair
  p0.resize(n);
  p1.resize(n);
  for (int i = 0; i < n; ++i) {
    p0[i] = proj(v0[loop[i]]);
    p1[i] = proj(v1[loop[i]]);
  }
  // Orientation of endpoint q against edge (r, s) over [0, 1].
  auto orient = [&](int r, int s, int q) {
    return det_quadratic(v0[s] - v0[r], v1[s] - v1[r], v0[q] - v0[r], v1[q] - v1[r], axis).sign();
  };
  return for_each_near_edge_pair(p0, p1, 1e-12 * scale + 1e-300, [&](int i, int j) {
    const int p = loop[i], q = loop[(i + 1) % n], r = loop[j], s = loop[(j + 1) % n];
    const int op = orient(r, s, p), oq = orient(r, s, q), orr = orient(p, q, r),
              os = orient(p, q, s);
    if (op == 0 || oq == 0 || orr == 0 || os == 0) return false;
    return !(op != oq && orr != os);  // false where the segments cross
  });
}

}  // namespace clothcd::detail
