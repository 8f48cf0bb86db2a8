// The optimal (minimal) cone of a set of directions: Welzl's move-to-front algorithm run on the
// sphere with caps through one, two or three points (docs/algorithms.md 4).
//
// For caps below pi/2 the minimal cap equals the minimum enclosing ball of the unit tips
// (B(cos t c, sin t)), so this is the same LP-type problem. Working with caps directly avoids two
// numerical traps of the ball form: acos|q| cannot resolve half-angles below ~1e-8 rad, and four
// co-circular tips (always the case for a support set of 4) make the circumsphere singular.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "clothcd/geometry/angle.hpp"
#include "clothcd/geometry/cone.hpp"
#include "sphere_caps.hpp"
#include "validate.hpp"

namespace clothcd {

namespace {

// A cap with its tangent cached for the containment test.
struct Cap {
  Eigen::Vector3d axis;
  double half_angle;
  double tan_half;
};

Cap make_cap(const NormalCone& c) {
  return {c.axis, c.half_angle, std::tan(c.half_angle)};
}

// Angle test in tangent form, exact at tiny angles (a dot-product test cannot tell 1e-9 rad
// from 0). The tolerance, 1e-14 rad mapped to tangent space, keeps rim points (and repeated
// directions) inside; the final pass restores exact containment.
bool inside(const Cap& cap, const Eigen::Vector3d& p) {
  const double d = cap.axis.dot(p);
  if (!(d > 0.0)) return false;
  const double tan_tol = 1e-14 * (1.0 + cap.tan_half * cap.tan_half);
  const double bound = (cap.tan_half + tan_tol) * d;
  return precise_cross(cap.axis, p).squaredNorm() <= bound * bound;
}

// SplitMix64: a fixed, portable generator, so the result never depends on the standard library.
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
};

// Welzl may settle on a support triple of nearly coincident rim points (co-circular sets), whose
// circumcap is ill-conditioned: its axis can be off by ~eps (R / d)^2. Rebuild the cap from the
// most spread-out rim points and keep it when it needs a smaller half-angle.
void polish(const std::vector<Eigen::Vector3d>& pts, NormalCone& best) {
  const double rim_angle = best.half_angle * (1.0 - 1e-7) - 1e-15;
  std::vector<Eigen::Vector3d> rim;
  for (const Eigen::Vector3d& p : pts) {
    if (angle_between(best.axis, p) >= rim_angle) rim.push_back(p);
  }
  if (rim.size() < 2) return;
  auto farthest_from = [&](auto&& distance) {
    std::size_t arg = 0;
    double far = -1.0;
    for (std::size_t i = 0; i < rim.size(); ++i) {
      if (const double d = distance(rim[i]); d > far) far = d, arg = i;
    }
    return rim[arg];
  };
  const Eigen::Vector3d p1 = rim[0];
  const Eigen::Vector3d p2 = farthest_from([&](const auto& x) { return angle_between(p1, x); });
  const Eigen::Vector3d p3 = farthest_from(
      [&](const auto& x) { return std::min(angle_between(p1, x), angle_between(p2, x)); });
  for (const NormalCone& c : {detail::diametral_cap(p1, p2), detail::circumcap(p1, p2, p3),
                              detail::circumcap(p3, p1, p2)}) {
    if (c.saturated()) continue;
    const double theta = detail::max_angle_from(c.axis, pts.data(), pts.size());
    if (theta < best.half_angle) best = {c.axis, theta};
  }
}

}  // namespace

NormalCone optimal_cone(std::span<const Eigen::Vector3d> unit_vectors) {
  if (unit_vectors.empty()) {
    throw std::invalid_argument("optimal_cone: the vector set is empty (no cone encloses it)");
  }
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(unit_vectors.size());
  bool has_zero = false;
  for (std::size_t i = 0; i < unit_vectors.size(); ++i) {
    const Eigen::Vector3d& v = unit_vectors[i];
    if (!v.allFinite()) {
      throw std::invalid_argument(fmt::format(
          "optimal_cone: vector {} must be finite, got ({}, {}, {})", i, v.x(), v.y(), v.z()));
    }
    const double n2 = v.squaredNorm();
    if (!(n2 > 1e-280)) {
      has_zero = true;
      continue;
    }
    pts.push_back(std::abs(n2 - 1.0) > 1e-14 ? Eigen::Vector3d(v / std::sqrt(n2)) : v);
  }
  if (has_zero) return saturated_cone();  // a zero vector has no direction

  // Random order makes the expected number of cap recomputations linear; a fixed seed keeps the
  // result reproducible.
  SplitMix64 rng{0x5DEECE66DULL ^ pts.size()};
  for (std::size_t i = pts.size(); i > 1; --i) {
    std::swap(pts[i - 1], pts[rng.next() % i]);
  }

  const std::size_t n = pts.size();
  Cap cap{pts[0], 0.0, 0.0};
  for (std::size_t i = 1; i < n; ++i) {
    if (inside(cap, pts[i])) continue;
    cap = {pts[i], 0.0, 0.0};
    for (std::size_t j = 0; j < i; ++j) {
      if (inside(cap, pts[j])) continue;
      // Welzl's constrained caps never exceed the minimal cap of the whole set, so a diametral
      // cap reaching pi/2 (antiparallel directions) proves the set saturates.
      const NormalCone two = detail::diametral_cap(pts[i], pts[j]);
      if (two.saturated()) return saturated_cone(two.axis);
      cap = make_cap(two);
      for (std::size_t k = 0; k < j; ++k) {
        if (inside(cap, pts[k])) continue;
        // The cap with p_i, p_j, p_k on its rim. When rounding leaves that circle undefined
        // (p_k nearly repeats p_i or p_j, or the three are nearly on a great circle), widen the
        // current cap just enough instead: sound, and the loss is the size of the rounding.
        NormalCone three = detail::circumcap(pts[i], pts[j], pts[k]);
        if (three.saturated()) {
          three = {cap.axis, std::max(cap.half_angle, angle_between(cap.axis, pts[k]))};
        }
        if (three.saturated()) return saturated_cone(three.axis);
        cap = make_cap(three);
      }
    }
  }

  // Exact half-angle for the axis found: the largest angle to any input. When the set spans a
  // hemisphere (0 in its hull) every axis has an input on or behind its equator.
  NormalCone best{cap.axis, detail::max_angle_from(cap.axis, pts.data(), n)};
  if (best.saturated()) return saturated_cone(cap.axis);
  polish(pts, best);
  return {best.axis, best.half_angle + kConeSlack};
}

}  // namespace clothcd
