// Leaf cones: the cone of a triangle's normal over a linear motion (CCD, docs/algorithms.md 3.3)
// and of a static triangle (DCD).
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "clothcd/geometry/cone.hpp"
#include "sphere_caps.hpp"
#include "validate.hpp"

namespace clothcd {

namespace {

constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() / 2;

// Forward error bound of a computed cross product e1 x e2 of rounded edge differences: each edge
// carries a relative error <= u (one subtraction), each component of the cross product
// <= 4u (|x1 y2| + |x2 y1|), and the vector of those magnitudes is at most 2 |e1||e2| long.
// A safety factor of two on top. Products that fall below the normal range lose relative
// precision: each rounds with an absolute error up to half the smallest subnormal, so a few of
// those are added (a fuzzed step whose end normal had components of a few subnormals got a
// cone that missed that normal by 1.6e-10 rad).
double cross_error(double e1_len, double e2_len) {
  return 16.0 * kUnitRoundoff * e1_len * e2_len + 8.0 * std::numeric_limits<double>::denorm_min();
}

// The angle by which a vector of length `len`, known to within `err`, may differ in direction
// from the true one; pi/2 (saturating) when the error may reach the vector.
double direction_error(double len, double err) {
  if (!(len > err)) return kSaturatedHalfAngle;
  return std::asin(err / len);
}

// |v| without overflow or underflow of the squared norm: coordinates beyond ~1e154 square past
// 1e308, and below ~1e-150 their squares lose bits in subnormals (a fuzzed near-degenerate
// triangle got a normal 1.0002 long, so its leaf cone missed the true normal).
double safe_norm(const Eigen::Vector3d& v) {
  const double n = v.norm();
  return std::isfinite(n) && n > 1e-140 ? n : v.stableNorm();
}

// A saturated-or-final leaf cone: `theta` plus slack, clamped to the canonical saturated form.
NormalCone leaf_result(const Eigen::Vector3d& axis, double theta) {
  theta += kConeSlack;
  if (!(theta < kSaturatedHalfAngle)) return saturated_cone(axis);
  return {axis, theta};
}

NormalCone cone_of_directions(const Eigen::Vector3d& d0, const Eigen::Vector3d& d1,
                              const Eigen::Vector3d* dx, LeafConePolicy policy) {
  switch (policy) {
    case LeafConePolicy::Tang: {
      const NormalCone c = merge_provot({d0, 0.0}, {d1, 0.0});
      return dx != nullptr ? merge_provot(c, {*dx, 0.0}) : c;
    }
    case LeafConePolicy::Proposed: {
      const NormalCone c = merge_tight({d0, 0.0}, {d1, 0.0});
      return dx != nullptr ? merge_tight(c, {*dx, 0.0}) : c;
    }
    case LeafConePolicy::Exact:
      return detail::minimal_cap(d0, d1, dx);
  }
  return saturated_cone(d0);
}

}  // namespace

BernsteinNormal bernstein_normal(const Eigen::Vector3d& a_t0, const Eigen::Vector3d& b_t0,
                                 const Eigen::Vector3d& c_t0, const Eigen::Vector3d& a_t1,
                                 const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1) {
  const Eigen::Vector3d e1_t0 = b_t0 - a_t0, e2_t0 = c_t0 - a_t0;
  const Eigen::Vector3d e1_t1 = b_t1 - a_t1, e2_t1 = c_t1 - a_t1;
  return {e1_t0.cross(e2_t0), 0.5 * (e1_t0.cross(e2_t1) + e1_t1.cross(e2_t0)), e1_t1.cross(e2_t1)};
}

NormalCone ccd_leaf_cone(const Eigen::Vector3d& a_t0, const Eigen::Vector3d& b_t0,
                         const Eigen::Vector3d& c_t0, const Eigen::Vector3d& a_t1,
                         const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1,
                         LeafConePolicy policy) {
  constexpr const char* fn = "ccd_leaf_cone";
  detail::require_finite(a_t0, fn, "a_t0");
  detail::require_finite(b_t0, fn, "b_t0");
  detail::require_finite(c_t0, fn, "c_t0");
  detail::require_finite(a_t1, fn, "a_t1");
  detail::require_finite(b_t1, fn, "b_t1");
  detail::require_finite(c_t1, fn, "c_t1");

  const Eigen::Vector3d e1_t0 = b_t0 - a_t0, e2_t0 = c_t0 - a_t0;
  const Eigen::Vector3d e1_t1 = b_t1 - a_t1, e2_t1 = c_t1 - a_t1;
  const double l10 = safe_norm(e1_t0), l20 = safe_norm(e2_t0), l11 = safe_norm(e1_t1),
               l21 = safe_norm(e2_t1);
  const BernsteinNormal n = bernstein_normal(a_t0, b_t0, c_t0, a_t1, b_t1, c_t1);
  if (!n.n0.allFinite() || !n.nx.allFinite() || !n.n1.allFinite()) {
    return saturated_cone();  // coordinates so large that the products overflow
  }

  // Degenerate at an end of the step: the normal is undefined there.
  const double len0 = safe_norm(n.n0), len1 = safe_norm(n.n1), lenx = safe_norm(n.nx);
  const double err0 = cross_error(l10, l20), err1 = cross_error(l11, l21);
  const double errx =
      0.5 * (cross_error(l10, l21) + cross_error(l11, l20)) + 2.0 * kUnitRoundoff * lenx;
  const double delta0 = direction_error(len0, err0), delta1 = direction_error(len1, err1);
  if (!(delta0 < kSaturatedHalfAngle) || !(delta1 < kSaturatedHalfAngle)) return saturated_cone();

  const Eigen::Vector3d d0 = n.n0 / len0, d1 = n.n1 / len1;
  if (lenx > errx) {
    // n(t) is a non-negative combination of n0, nx, n1: a cap (< pi/2) holding all three
    // directions, widened by their rounding, holds n(t) / |n(t)| for every t.
    const Eigen::Vector3d dx = n.nx / lenx;
    const NormalCone c = cone_of_directions(d0, d1, &dx, policy);
    if (c.saturated()) return c;
    const double delta = std::max({delta0, delta1, direction_error(lenx, errx)});
    return leaf_result(c.axis, c.half_angle + delta);
  }
  // nx is lost in rounding (|nx| <= 2 errx): drop it and widen by the most the middle term
  // 2t(1-t) nx can turn s^2 n0 + t^2 n1, whose length is >= cos(theta) 2ts sqrt(|n0||n1|).
  const NormalCone c = cone_of_directions(d0, d1, nullptr, policy);
  if (c.saturated()) return c;
  const double theta = c.half_angle + std::max(delta0, delta1);
  if (!(theta < kSaturatedHalfAngle)) return saturated_cone(c.axis);
  const double ratio =
      2.0 * errx / (std::cos(theta) * (std::sqrt(len0 - err0) * std::sqrt(len1 - err1)));
  if (!(ratio < 1.0)) return saturated_cone(c.axis);
  return leaf_result(c.axis, theta + std::asin(ratio));
}

NormalCone dcd_leaf_cone(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  constexpr const char* fn = "dcd_leaf_cone";
  detail::require_finite(a, fn, "a");
  detail::require_finite(b, fn, "b");
  detail::require_finite(c, fn, "c");
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d n = e1.cross(e2);
  if (!n.allFinite()) return saturated_cone();
  const double len = safe_norm(n);
  const double delta = direction_error(len, cross_error(safe_norm(e1), safe_norm(e2)));
  if (!(delta < kSaturatedHalfAngle)) return saturated_cone();
  return leaf_result(n / len, delta);
}

}  // namespace clothcd
