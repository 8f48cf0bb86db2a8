// Leaf cones: the cone of a triangle's normal over a linear motion (CCD, docs/algorithms.md 3.3)
// and of a static triangle (DCD).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "clothcd/geometry/angle.hpp"
#include "clothcd/geometry/cone.hpp"
#include "geometry/patch_block.hpp"
#include "patch_cone.hpp"
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

namespace detail {

NormalCone patch_ccd_cone(std::span<const std::array<int, 3>> faces, std::span<const int> ids,
                          std::span<const Eigen::Vector3d> v_t0,
                          std::span<const Eigen::Vector3d> v_t1) {
  if (ids.empty()) throw std::invalid_argument("patch_ccd_cone: no triangles");
  // The unnormalized control vectors with their squared lengths, and the cones of the triangles
  // left to ccd_leaf_cone (extreme scales, or a middle control vector lost in rounding; rare).
  // One scratch buffer a thread: no allocation once it has grown.
  struct Control {
    Eigen::Vector3d n;
    double q;  // |n|^2
  };
  thread_local std::vector<Control> controls;
  thread_local std::vector<NormalCone> cones;
  controls.clear();
  cones.clear();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double worst_ratio2 = 0;  // the largest (error / length)^2 of a control vector
  // The triangles' control vectors a block at a time in lanes (patch_block.hpp), then taken in
  // the triangles' order, so the sum rounds as one loop over them would.
  const int nt = static_cast<int>(ids.size());
  PatchBlock blk;
  for (int base = 0; base < nt; base += PatchBlock::kLanes) {
    const int count = std::min(PatchBlock::kLanes, nt - base);
    patch_block(faces.data(), ids.data() + base, count, v_t0.data(), v_t1.data(), blk);
    for (int l = 0; l < count; ++l) {
      // ccd_leaf_cone's error bounds, squared: (err0 / len0)^2 with err0 = 16 u l10 l20 (the
      // subnormal term vanishes within in_range's scales, far below the factor two of safety in
      // it), and errx / lenx <= 8 u sqrt(2 (s10 s21 + s11 s20) / qx) + 2 u, whose square is at
      // most twice the sum of the terms' squares.
      if (blk.in_range[l] != 0) {
        const double r0 = blk.r0[l], r1 = blk.r1[l], rx = blk.rx[l];
        if (!(r0 < 1) || !(r1 < 1)) return saturated_cone();  // an end normal may vanish
        if (rx < 1) {
          worst_ratio2 = std::max({worst_ratio2, r0, r1, rx});
          for (int i = 0; i < 3; ++i) {
            controls.push_back(
                {Eigen::Vector3d(blk.n[i][0][l], blk.n[i][1][l], blk.n[i][2][l]), blk.q[i][l]});
            sum += Eigen::Vector3d(blk.unit[i][0][l], blk.unit[i][1][l], blk.unit[i][2][l]);
          }
          continue;
        }
      }
      const std::array<int, 3>& t = faces[ids[base + l]];
      const Eigen::Vector3d &a0 = v_t0[t[0]], &b0 = v_t0[t[1]], &c0 = v_t0[t[2]];
      const Eigen::Vector3d &a1 = v_t1[t[0]], &b1 = v_t1[t[1]], &c1 = v_t1[t[2]];
      const NormalCone c = ccd_leaf_cone(a0, b0, c0, a1, b1, c1, LeafConePolicy::Exact);
      if (c.saturated()) return c;
      cones.push_back(c);
      sum += c.axis;
    }
  }
  const double norm = sum.norm();
  if (!(norm > 1e-3)) return saturated_cone();
  const Eigen::Vector3d axis = sum / norm;
  // Every direction at least ~1e-3 of a unit vector off the axis's orthogonal plane: below that,
  // the rounding of the sines below could matter (1 / cos of the angle bounds its effect).
  constexpr double kMinCosine = 1e-3;
  double worst_sine2 = 0;
  for (const Control& c : controls) {
    const double dot = axis.dot(c.n);
    if (!(dot > 0) || !(dot * dot > kMinCosine * kMinCosine * c.q)) return saturated_cone(axis);
    worst_sine2 = std::max(worst_sine2, axis.cross(c.n).squaredNorm() / c.q);
  }
  // Rounding of the axis, the cross products, the quotients and asin: a few ulps each, over a
  // cosine of at least kMinCosine.
  constexpr double kRounding = 1e-10;
  double theta = 0;
  if (!controls.empty()) {
    theta = std::asin(std::min(1.0, std::sqrt(worst_sine2))) +
            std::asin(std::min(1.0, std::sqrt(worst_ratio2))) + kRounding;
  }
  for (const NormalCone& c : cones) {
    theta = std::max(theta, angle_between(axis, c.axis) + c.half_angle + kRounding);
  }
  return leaf_result(axis, theta);
}

}  // namespace detail

}  // namespace clothcd
