// The optimal (minimal) cone of a set of directions: Welzl's randomized incremental algorithm on
// the sphere, with caps through one, two or three directions and a fourth level that proves
// saturation (docs/algorithms.md 4, docs/cones.md).
//
// Below pi/2 the minimal cap is an LP-type problem of combinatorial dimension 3 (its rim holds at
// most three support directions). Allowing the saturated answer ("no open hemisphere holds the
// set") raises the dimension to 4: four directions whose hull holds the origin. A three-level
// Welzl then has no level at which to notice saturation, and on such sets it keeps replacing caps
// that miss earlier points, which made it cubic. Working with caps rather than with the minimum
// enclosing ball of the tips avoids two numerical traps of the ball form: acos|q| cannot resolve
// half-angles below ~1e-8 rad, and four co-circular tips make the circumsphere singular.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "clothcd/geometry/angle.hpp"
#include "clothcd/geometry/cone.hpp"
#include "sphere_caps.hpp"
#include "validate.hpp"

namespace clothcd {

namespace {

// A cap with the tangent-space bound of the containment test cached.
struct Cap {
  Eigen::Vector3d axis;
  double half_angle;
  double tan_bound;  // tan(half_angle) plus the test's tolerance
};

// The containment tolerance: 1e-14 rad plus 1e-12 of the half-angle, mapped to tangent space. It
// keeps rim points and repeated directions inside despite the rounding of the cap, so rounding
// cannot make Welzl revisit its prefix over and over. The final pass measures the exact largest
// angle, so a point let in by the tolerance costs at most the tolerance, never containment.
Cap make_cap(const Eigen::Vector3d& axis, double half_angle) {
  const double t = std::tan(half_angle);
  return {axis, half_angle, t + (1e-14 + 1e-12 * half_angle) * (1.0 + t * t)};
}

// Angle test in tangent form, exact at tiny angles (a dot-product test cannot tell 1e-9 rad
// from 0).
bool inside(const Cap& cap, const Eigen::Vector3d& p) {
  const double d = cap.axis.dot(p);
  if (!(d > 0.0)) return false;
  const double bound = cap.tan_bound * d;
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

// The minimal cap of four directions by brute force over its possible supports (six pairs, four
// triples), each candidate's half-angle measured as the largest angle to the four. Saturated when
// no candidate stays below pi/2: then no open hemisphere holds the four, so none holds the set.
NormalCone minimal_cap4(const std::array<Eigen::Vector3d, 4>& q) {
  NormalCone best = saturated_cone(q[0]);
  auto consider = [&](const NormalCone& c) {
    if (c.saturated()) return;
    const double theta = detail::max_angle_from(c.axis, q.data(), q.size());
    if (theta < best.half_angle) best = {c.axis, theta};
  };
  for (int a = 0; a < 4; ++a) {
    for (int b = a + 1; b < 4; ++b) {
      consider(detail::diametral_cap(q[a], q[b]));
      for (int c = b + 1; c < 4; ++c)
        consider(detail::circumcap(q[a], q[b], q[c]));
    }
  }
  return best;
}

// The result of the randomized search: a cap containing every point (up to the tolerance), or
// a proof of saturation.
struct Search {
  Cap cap;
  bool saturated = false;
  // The points that fixed the last cap (-1: unused); ill-conditioned when nearly coincident.
  std::array<std::size_t, 3> support{};
  int support_size = 1;
  bool widened = false;  // a rounding fallback widened a cap: the support does not define it
};

// Welzl's algorithm, iterative: level 1 keeps the minimal cap of the prefix, level 2 the minimal
// cap with p_i on its rim, level 3 with p_i and p_j on its rim, level 4 checks the cap through
// p_i, p_j, p_k against the earlier points. Exact arithmetic never fails that check unless the
// set is saturated; rounding (nearly coincident or co-circular points) can, and then the cap is
// widened just enough, which is sound and loses only the size of the rounding.
Search welzl(const std::vector<Eigen::Vector3d>& pts) {
  const std::size_t n = pts.size();
  Search s{make_cap(pts[0], 0.0)};
  s.support = {0, 0, 0};
  auto saturate = [&](const Eigen::Vector3d& axis) {
    s.cap = {axis, kSaturatedHalfAngle, 0.0};
    s.saturated = true;
    return s;
  };
  for (std::size_t i = 1; i < n; ++i) {
    if (inside(s.cap, pts[i])) continue;
    s.cap = make_cap(pts[i], 0.0);
    s.support = {i, i, i};
    s.support_size = 1;
    s.widened = false;
    for (std::size_t j = 0; j < i; ++j) {
      if (inside(s.cap, pts[j])) continue;
      // Antiparallel directions: no open hemisphere holds both.
      const NormalCone two = detail::diametral_cap(pts[i], pts[j]);
      if (two.saturated()) return saturate(two.axis);
      s.cap = make_cap(two.axis, two.half_angle);
      s.support = {i, j, j};
      s.support_size = 2;
      s.widened = false;
      for (std::size_t k = 0; k < j; ++k) {
        if (inside(s.cap, pts[k])) continue;
        const NormalCone three = detail::circumcap(pts[i], pts[j], pts[k]);
        if (three.saturated()) {
          // No cap below pi/2 has the three on its rim: they lie on a great circle (saturated
          // when they do not fit in a half of it) or rounding left the circle undefined.
          if (detail::minimal_cap(pts[i], pts[j], &pts[k]).saturated()) return saturate(pts[i]);
          s.cap =
              make_cap(s.cap.axis, std::max(s.cap.half_angle, angle_between(s.cap.axis, pts[k])));
          s.widened = true;
          continue;
        }
        s.cap = make_cap(three.axis, three.half_angle);
        s.support = {i, j, k};
        s.support_size = 3;
        s.widened = false;
        for (std::size_t l = 0; l < k; ++l) {
          if (inside(s.cap, pts[l])) continue;
          if (minimal_cap4({pts[i], pts[j], pts[k], pts[l]}).saturated()) {
            return saturate(s.cap.axis);
          }
          s.cap = make_cap(s.cap.axis, angle_between(s.cap.axis, pts[l]));
          s.widened = true;
        }
      }
    }
  }
  return s;
}

// tan of the angle from unit `axis` to unit `p` (infinite at or behind the equator).
double tan_from(const Eigen::Vector3d& axis, const Eigen::Vector3d& p) {
  const double d = axis.dot(p);
  if (!(d > 0.0)) return std::numeric_limits<double>::infinity();
  return precise_cross(axis, p).norm() / d;
}

// Welzl may settle on a support triple of nearly coincident rim points (co-circular sets), whose
// circumcap is ill-conditioned: its axis can be off by ~eps (R / d)^2. Rebuild the cap from the
// most spread-out rim points and keep it when it needs a smaller half-angle. Only run when the
// support is ill-conditioned or was widened: it costs three more passes over the set.
void polish(const std::vector<Eigen::Vector3d>& pts, NormalCone& best) {
  const double rim_tan = std::tan(best.half_angle * (1.0 - 1e-7) - 1e-15);
  std::vector<Eigen::Vector3d> rim;
  for (const Eigen::Vector3d& p : pts) {
    if (tan_from(best.axis, p) >= rim_tan) rim.push_back(p);
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

// Whether the cap Welzl ended on may be off the optimum by more than rounding: a rounding
// fallback widened it, two support points nearly coincide (their circumcap is ill-conditioned),
// or the support points are not all on the rim of the cap through them (a circumcap near pi/2
// can be off by ~1e-11 rad).
bool ill_conditioned(const std::vector<Eigen::Vector3d>& pts, const Search& s) {
  if (s.widened) return true;
  if (s.support_size < 2) return false;
  const Eigen::Vector3d& axis = s.cap.axis;
  double lo = angle_between(axis, pts[s.support[0]]), hi = lo;
  for (int r = 1; r < s.support_size; ++r) {
    const double a = angle_between(axis, pts[s.support[r]]);
    lo = std::min(lo, a), hi = std::max(hi, a);
  }
  if (hi - lo > 1e-13 * hi + 1e-16) return true;
  if (s.support_size < 3) return false;
  const Eigen::Vector3d &a = pts[s.support[0]], &b = pts[s.support[1]], &c = pts[s.support[2]];
  const double closest = std::min({angle_between(a, b), angle_between(b, c), angle_between(a, c)});
  return closest < 0.05 * s.cap.half_angle;
}

// Reads, checks and normalizes the input into `pts`, the hinted directions first (in the given
// order), the rest in a seeded random order. False when a zero vector makes the cone saturated.
bool prepare(std::span<const Eigen::Vector3d> in, std::span<const std::size_t> first,
             std::vector<Eigen::Vector3d>& pts) {
  pts.clear();
  pts.reserve(in.size());
  bool has_zero = false;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Eigen::Vector3d& v = in[i];
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
  if (has_zero) return false;
  // Random order makes the expected number of cap recomputations linear; a seed fixed by the
  // size keeps the result reproducible.
  SplitMix64 rng{0x5DEECE66DULL ^ pts.size()};
  for (std::size_t i = pts.size(); i > 1; --i) {
    std::swap(pts[i - 1], pts[rng.next() % i]);
  }
  // Hints go to the front afterwards, so the rest keeps the same seeded order whatever the hint.
  std::size_t front = 0;
  for (std::size_t h : first) {
    const Eigen::Vector3d& v = in[h];
    const double n2 = v.squaredNorm();
    pts.push_back(pts[front]);
    pts[front++] = std::abs(n2 - 1.0) > 1e-14 ? Eigen::Vector3d(v / std::sqrt(n2)) : v;
  }
  return true;
}

NormalCone solve(std::span<const Eigen::Vector3d> unit_vectors,
                 std::span<const std::size_t> first) {
  if (unit_vectors.empty()) {
    throw std::invalid_argument("optimal_cone: the vector set is empty (no cone encloses it)");
  }
  thread_local std::vector<Eigen::Vector3d> pts;  // reused: a tree refit calls this per node
  if (!prepare(unit_vectors, first, pts)) return saturated_cone();  // a zero vector
  const Search s = welzl(pts);
  if (s.saturated) return saturated_cone(s.cap.axis);
  // Exact half-angle for the axis found: the largest angle to any input. When the set spans a
  // hemisphere (0 in its hull) every axis has an input on or behind its equator.
  NormalCone best{s.cap.axis, detail::max_angle_from(s.cap.axis, pts.data(), pts.size())};
  if (best.saturated()) return saturated_cone(s.cap.axis);
  if (ill_conditioned(pts, s)) polish(pts, best);
  return {best.axis, best.half_angle + kConeSlack};
}

}  // namespace

NormalCone optimal_cone(std::span<const Eigen::Vector3d> unit_vectors) {
  return solve(unit_vectors, {});
}

NormalCone optimal_cone(std::span<const Eigen::Vector3d> unit_vectors,
                        std::span<const ConePart> parts) {
  std::size_t total = 0;
  for (const ConePart& part : parts)
    total += part.count;
  if (total != unit_vectors.size()) {
    throw std::invalid_argument(fmt::format("optimal_cone: the parts hold {} vectors, the set {}",
                                            total, unit_vectors.size()));
  }
  // Each part's three directions farthest from its cone's axis (its support when the cone is
  // optimal): the node's support is usually among them, and Welzl started on them rarely has to
  // revisit the rest.
  std::vector<std::size_t> first;
  std::size_t begin = 0;
  for (const ConePart& part : parts) {
    if (!part.cone.saturated() && part.count > 0) {
      std::array<std::size_t, 3> arg{};
      std::array<double, 3> far{-1.0, -1.0, -1.0};
      for (std::size_t i = begin; i < begin + part.count; ++i) {
        const Eigen::Vector3d& v = unit_vectors[i];
        if (!v.allFinite()) break;  // reported by the main pass
        const double t = tan_from(part.cone.axis, v.normalized());
        // Insertion into the top three, ties to the earlier index: deterministic.
        for (int r = 0; r < 3; ++r) {
          if (t > far[r]) {
            for (int m = 2; m > r; --m)
              far[m] = far[m - 1], arg[m] = arg[m - 1];
            far[r] = t, arg[r] = i;
            break;
          }
        }
      }
      for (int r = 0; r < 3 && r < static_cast<int>(part.count); ++r)
        first.push_back(arg[r]);
    }
    begin += part.count;
  }
  return solve(unit_vectors, first);
}

}  // namespace clothcd
