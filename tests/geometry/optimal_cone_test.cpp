// Property tests of the optimal cone (algorithms.md 4): minimal against a brute-force search over
// every pair and triple, never wider than a hierarchical merge, saturated exactly when the set
// spans a hemisphere, and deterministic.
#include <gtest/gtest.h>

#include <iomanip>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "clothcd/geometry/cone.hpp"
#include "cone_sampling.hpp"

namespace clothcd {
namespace {

using test::angle_ld;
using test::kCases;
using test::Rng;
using test::to_ld;
using test::Vec3L;

using Vec2L = Eigen::Matrix<long double, 2, 1>;

// `n` directions within angle `spread` of a random centre; some repeated, some on the rim (the
// co-circular degenerate case of the ball formulation).
std::vector<Eigen::Vector3d> random_set(Rng& rng, int n, double spread) {
  const Eigen::Vector3d centre = rng.unit();
  std::vector<Eigen::Vector3d> v;
  const bool cocircular = rng.chance(0.2);
  for (int i = 0; i < n; ++i) {
    if (i > 0 && rng.chance(0.05)) {
      v.push_back(v[rng.integer(0, i - 1)]);  // repeated direction
      continue;
    }
    const double angle = cocircular ? spread : spread * std::sqrt(rng.uniform());
    Eigen::Vector3d p = test::rotate(centre, rng.perpendicular(centre), angle);
    if (rng.chance(0.1)) p *= rng.log_uniform(1e-3, 1e3);  // not unit: only directions count
    v.push_back(p);
  }
  return v;
}

// The largest angle from `axis` to the set (the half-angle a cone with that axis needs). Every
// angle is evaluated: picking the smallest dot product first cannot resolve tiny angles.
long double needed(const Vec3L& axis, const std::vector<Vec3L>& pts) {
  long double worst = 0;
  for (const Vec3L& p : pts)
    worst = std::max(worst, angle_ld(axis, p));
  return worst;
}

// Brute-force minimal cap on the sphere: every point, every pair midpoint and every triple's
// circumcentre as a candidate axis. Accurate to ~1e-19 / s^2 relative at scale s.
long double brute_force_spherical(const std::vector<Vec3L>& pts) {
  const std::size_t n = pts.size();
  long double best = needed(pts[0], pts);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const Vec3L mid = pts[i] + pts[j];
      if (mid.norm() > 1e-12L) best = std::min(best, needed(mid.normalized(), pts));
      for (std::size_t k = j + 1; k < n; ++k) {
        Vec3L c = (pts[j] - pts[i]).cross(pts[k] - pts[i]);
        if (c.norm() < 1e-300L) continue;
        c.normalize();
        if (c.dot(pts[i]) < 0) c = -c;
        best = std::min(best, needed(c, pts));
      }
    }
  }
  return best;
}

// Brute-force minimal enclosing circle of the orthographic projections on the tangent plane at
// the first point: accurate to ~s^2 relative, the right oracle for tiny sets.
long double brute_force_planar(const std::vector<Vec3L>& pts) {
  const Vec3L c0 = pts[0];
  const Vec3L u = c0.unitOrthogonal(), v = c0.cross(u);
  std::vector<Vec2L> q;
  for (const Vec3L& p : pts)
    q.emplace_back(u.dot(p), v.dot(p));
  auto radius = [&](const Vec2L& centre) {
    long double r = 0;
    for (const Vec2L& x : q)
      r = std::max(r, (x - centre).norm());
    return r;
  };
  const std::size_t n = q.size();
  long double best = radius(q[0]);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      best = std::min(best, radius((q[i] + q[j]) / 2));
      for (std::size_t k = j + 1; k < n; ++k) {
        const Vec2L b = q[j] - q[i], c = q[k] - q[i];
        const long double d = 2 * (b.x() * c.y() - b.y() * c.x());
        if (std::abs(d) < 1e-300L) continue;
        const Vec2L m((c.y() * b.squaredNorm() - b.y() * c.squaredNorm()) / d,
                      (b.x() * c.squaredNorm() - c.x() * b.squaredNorm()) / d);
        best = std::min(best, radius(q[i] + m));
      }
    }
  }
  return best;
}

std::vector<Vec3L> unit_ld(const std::vector<Eigen::Vector3d>& v) {
  std::vector<Vec3L> out;
  for (const auto& p : v)
    out.push_back(to_ld(p).normalized());
  return out;
}

TEST(OptimalCone, MatchesBruteForceOnSmallSets) {
  int compared = 0;
  for (int seed = 0; seed < kCases; ++seed) {
    Rng rng(seed);
    const int n = rng.integer(1, 8);
    const double spread = rng.log_uniform(1e-9, 1.2 * std::numbers::pi / 2);
    const auto set = random_set(rng, n, spread);
    const NormalCone c = optimal_cone(set);
    const auto pts = unit_ld(set);
    // Containment, exact up to the long-double oracle.
    if (!c.saturated()) {
      ASSERT_LE(needed(to_ld(c.axis), pts), c.half_angle)
          << std::setprecision(17) << "seed " << seed;
    }
    const long double brute = spread > 2e-5 ? brute_force_spherical(pts) : brute_force_planar(pts);
    const long double tol = 1e-14L + 2e-9L * brute;
    if (c.saturated()) {
      ASSERT_GE(brute + tol, std::numbers::pi / 2 - 1e-9)
          << std::setprecision(17) << "seed " << seed;
      continue;
    }
    ++compared;
    ASSERT_NEAR(static_cast<double>(c.half_angle - kConeSlack), static_cast<double>(brute),
                static_cast<double>(tol))
        << std::setprecision(17) << "seed " << seed << " n " << n << " spread " << spread;
  }
  EXPECT_GT(compared, kCases / 2);
}

// A random binary tree over the set, merged bottom-up with `merge`.
NormalCone hierarchical(std::vector<NormalCone> cones, ConeMerge merge, Rng& rng) {
  while (cones.size() > 1) {
    const std::size_t i = rng.integer(0, static_cast<int>(cones.size()) - 2);
    cones[i] = merge_cones(cones[i], cones[i + 1], merge);
    cones.erase(cones.begin() + static_cast<std::ptrdiff_t>(i) + 1);
  }
  return cones[0];
}

TEST(OptimalCone, NeverWiderThanAHierarchicalMerge) {
  for (int seed = 0; seed < kCases; ++seed) {
    Rng rng(seed);
    const int n = rng.integer(2, 24);
    const auto set = random_set(rng, n, rng.log_uniform(1e-9, std::numbers::pi / 2));
    std::vector<NormalCone> leaves;
    for (const auto& p : set)
      leaves.push_back({p.normalized(), 0.0});
    const NormalCone opt = optimal_cone(set);
    for (const auto merge : {ConeMerge::Provot, ConeMerge::Tight}) {
      const NormalCone h = hierarchical(leaves, merge, rng);
      ASSERT_LE(opt.half_angle, h.half_angle + 1e-15) << std::setprecision(17) << "seed " << seed;
    }
    if (!opt.saturated()) {
      ASSERT_LE(needed(to_ld(opt.axis), unit_ld(set)), opt.half_angle)
          << std::setprecision(17) << "seed " << seed;
    }
  }
}

TEST(OptimalCone, HemisphereSpanningSetsSaturate) {
  for (int seed = 0; seed < kCases; ++seed) {
    Rng rng(seed);
    // 0 in the convex hull: the last vector is minus a positive combination of the others.
    auto set = random_set(rng, rng.integer(1, 6), rng.log_uniform(1e-9, std::numbers::pi));
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& p : set)
      sum += rng.log_uniform(1e-3, 1.0) * p.normalized();
    if (sum.norm() < 1e-6) continue;
    set.insert(set.begin() + rng.integer(0, static_cast<int>(set.size())), -sum);
    ASSERT_TRUE(optimal_cone(set).saturated()) << std::setprecision(17) << "seed " << seed;
  }
}

TEST(OptimalCone, SetsInsideAnOpenHemisphereDoNotSaturate) {
  for (int seed = 0; seed < kCases / 10; ++seed) {
    Rng rng(seed);
    // Directions at least `margin` above the equator of a random pole.
    const double margin = rng.log_uniform(1e-6, 0.5);
    const Eigen::Vector3d pole = rng.unit();
    std::vector<Eigen::Vector3d> set;
    const int n = rng.integer(1, 40);
    for (int i = 0; i < n; ++i) {
      const double angle = rng.chance(0.5) ? std::numbers::pi / 2 - margin
                                           : rng.uniform(0.0, std::numbers::pi / 2 - margin);
      set.push_back(test::rotate(pole, rng.perpendicular(pole), angle));
    }
    const NormalCone c = optimal_cone(set);
    ASSERT_FALSE(c.saturated()) << std::setprecision(17) << "seed " << seed;
    // Near the equator the cap is ill-conditioned: its axis moves by ~eps / cos(theta).
    ASSERT_LE(c.half_angle, std::numbers::pi / 2 - margin + 2 * kConeSlack + 1e-15 / margin)
        << std::setprecision(17) << "seed " << seed << " margin " << margin << " n " << n
        << " excess " << c.half_angle - (std::numbers::pi / 2 - margin);
  }
}

TEST(OptimalCone, LargeSetsAreLocallyOptimalAndDeterministic) {
  for (int seed = 0; seed < 20; ++seed) {
    Rng rng(seed);
    const auto set = random_set(rng, 10'000, rng.log_uniform(1e-9, 1.2));
    const NormalCone c = optimal_cone(set);
    const NormalCone again = optimal_cone(set);
    ASSERT_EQ(c.axis, again.axis);
    ASSERT_EQ(c.half_angle, again.half_angle);
    ASSERT_FALSE(c.saturated());
    const auto pts = unit_ld(set);
    const long double theta = needed(to_ld(c.axis), pts);
    ASSERT_LE(theta, c.half_angle) << std::setprecision(17) << "seed " << seed;
    // Optimality certificate: on a convex problem no nearby axis needs less.
    for (int k = 0; k < 24; ++k) {
      const Vec3L a = to_ld(c.axis);
      const Vec3L dir = a.cross(to_ld(rng.unit())).normalized();
      const long double step = theta * std::pow(10.0L, -(k % 6));
      const Vec3L probe = (std::cos(step) * a + std::sin(step) * dir).normalized();
      ASSERT_GE(needed(probe, pts), theta * (1 - 1e-9L) - 1e-15L)
          << std::setprecision(17) << "seed " << seed;
    }
    // The order of the input does not matter (beyond rounding).
    auto shuffled = set;
    std::reverse(shuffled.begin(), shuffled.end());
    ASSERT_NEAR(optimal_cone(shuffled).half_angle, c.half_angle, 1e-14 + 1e-12 * c.half_angle);
  }
}

}  // namespace
}  // namespace clothcd
