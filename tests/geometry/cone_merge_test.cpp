// Property tests of the binary cone merges (docs/algorithms.md 3.1, 3.2): containment, the paper's
// Theorem 1 with its exact difference D, and minimality against a brute-force search.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "clothcd/geometry/angle.hpp"
#include "clothcd/geometry/cone.hpp"
#include "cone_sampling.hpp"

namespace clothcd {
namespace {

using test::angle_ld;
using test::kCases;
using test::Rng;
using test::Vec3L;

// Every sampled rim point of `in` lies in `out` with no tolerance: the merge's slack must absorb
// all rounding. Returns the number of violations.
int count_escapes(const NormalCone& out, const NormalCone& in, Rng& rng) {
  if (out.saturated()) return 0;
  int escapes = 0;
  const double phase = rng.uniform(0.0, 2.0 * std::numbers::pi);
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d p = test::rim_point(in, phase + k * std::numbers::pi / 4);
    if (angle_ld(out.axis, p) > out.half_angle) ++escapes;
  }
  if (angle_ld(out.axis, in.axis) > out.half_angle) ++escapes;
  return escapes;
}

TEST(ConeMerge, EveryMergeContainsBothCones) {
  int unsaturated[2] = {0, 0};
  for (int seed = 0; seed < kCases; ++seed) {
    Rng rng(seed);
    const auto [a, b, scale] = test::random_cone_pair(rng);
    for (const ConeMerge policy : {ConeMerge::Provot, ConeMerge::Tight}) {
      const NormalCone m = merge_cones(a, b, policy);
      ASSERT_TRUE(m.axis.allFinite() && std::isfinite(m.half_angle)) << "seed " << seed;
      ASSERT_NEAR(m.axis.norm(), 1.0, 1e-14) << "seed " << seed;
      if (!m.saturated()) ++unsaturated[static_cast<int>(policy)];
      ASSERT_EQ(count_escapes(m, a, rng) + count_escapes(m, b, rng), 0)
          << "seed " << seed << " policy " << static_cast<int>(policy) << " scale " << scale;
    }
  }
  // The generator must exercise the interesting (unsaturated) regime most of the time.
  EXPECT_GT(unsaturated[0], kCases / 2);
  EXPECT_GT(unsaturated[1], kCases / 2);
}

TEST(ConeMerge, TightNeverWiderThanProvotAndDiffersByD) {
  for (int seed = 0; seed < kCases; ++seed) {
    Rng rng(seed);
    const auto [a, b, scale] = test::random_cone_pair(rng);
    const NormalCone provot = merge_provot(a, b);
    const NormalCone tight = merge_tight(a, b);
    ASSERT_LE(tight.half_angle, provot.half_angle) << "seed " << seed;
    if (provot.saturated()) continue;
    ASSERT_FALSE(tight.saturated()) << "seed " << seed;
    // The paper's D: beta/2 when one cone holds the other, |t1 - t2|/2 otherwise.
    const double beta = static_cast<double>(angle_ld(a.axis, b.axis));
    const double t1 = a.half_angle, t2 = b.half_angle;
    const bool inclusive = beta + t2 <= t1 || beta + t1 <= t2;
    const double d = inclusive ? beta / 2 : std::abs(t1 - t2) / 2;
    ASSERT_NEAR(provot.half_angle - tight.half_angle, d, 1e-14 + 1e-14 * provot.half_angle)
        << "seed " << seed << " inclusive " << inclusive;
  }
}

TEST(ConeMerge, ProvotAxisIsTheNormalizedSum) {
  for (int seed = 0; seed < kCases; ++seed) {
    Rng rng(seed);
    const auto [a, b, scale] = test::random_cone_pair(rng);
    const NormalCone m = merge_provot(a, b);
    const Eigen::Vector3d sum = a.axis + b.axis;
    if (m.saturated() || sum.norm() < 0.1) continue;
    ASSERT_LE(angle_ld(m.axis, sum), 1e-14) << "seed " << seed;
  }
}

// The smallest half-angle a cone with axis `x` needs to hold both cones: the farthest point of
// a cap B(a, t) from x is at angle(x, a) + t.
long double needed(const Vec3L& x, const NormalCone& a, const NormalCone& b) {
  return std::max(angle_ld(x, test::to_ld(a.axis)) + a.half_angle,
                  angle_ld(x, test::to_ld(b.axis)) + b.half_angle);
}

// Brute-force minimal enclosing cone: a search over the great circle through the axes (a coarse
// grid over the whole circle and a fine one at the pair's own scale, in double), refined by
// golden section in long double; returns the axis and the needed half-angle.
std::pair<Vec3L, long double> brute_force_minimum(const NormalCone& a, const NormalCone& b) {
  const Vec3L a1 = test::to_ld(a.axis).normalized();
  Vec3L w = a1.cross(test::to_ld(b.axis)).cross(a1);
  if (w.norm() < 1e-300L) w = a1.unitOrthogonal();
  w.normalize();
  auto point = [&](long double phi) -> Vec3L { return std::cos(phi) * a1 + std::sin(phi) * w; };
  auto f = [&](long double phi) { return needed(point(phi), a, b); };
  const Eigen::Vector3d a1d = a1.cast<double>(), wd = w.cast<double>();
  auto f_coarse = [&](double phi) {
    const Eigen::Vector3d x = std::cos(phi) * a1d + std::sin(phi) * wd;
    return std::max(angle_between(x, a.axis) + a.half_angle,
                    angle_between(x, b.axis) + b.half_angle);
  };
  double best_phi = 0, best = f_coarse(0), h = 0;
  const double beta = angle_between(a.axis, b.axis);
  for (int i = 1; i < 64; ++i) {
    const double phi = -std::numbers::pi + 2 * std::numbers::pi * i / 64;
    if (const double v = f_coarse(phi); v < best)
      best = v, best_phi = phi, h = 2 * std::numbers::pi / 64;
  }
  const double fine = std::max(beta, std::max(a.half_angle, b.half_angle)) / 32;
  for (int i = -64; i <= 64; ++i) {
    const double phi = fine * i;
    if (const double v = f_coarse(phi); v < best) best = v, best_phi = phi, h = fine;
  }
  if (h == 0) h = fine;
  h = std::max(h, 1e-300);
  long double lo = best_phi - h, hi = best_phi + h;
  const long double g = (std::sqrt(5.0L) - 1) / 2;
  long double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
  long double f1 = f(m1), f2 = f(m2);
  const long double stop = 1e-16L * (best + 1e-30);
  for (int it = 0; it < 300 && hi - lo > stop; ++it) {
    if (f1 < f2) {
      hi = m2, m2 = m1, f2 = f1;
      m1 = hi - g * (hi - lo), f1 = f(m1);
    } else {
      lo = m1, m1 = m2, f1 = f2;
      m2 = lo + g * (hi - lo), f2 = f(m2);
    }
  }
  const long double phi = (lo + hi) / 2;
  return {point(phi), f(phi)};
}

TEST(ConeMerge, TightEqualsBruteForceMinimalCone) {
#ifdef CLOTHCD_TEST_SANITIZED
  constexpr int kBruteCases = kCases / 5;
#else
  constexpr int kBruteCases = kCases;
#endif
  int compared = 0;
  for (int seed = 0; seed < kBruteCases; ++seed) {
    Rng rng(seed);
    const auto [a, b, scale] = test::random_cone_pair(rng);
    const NormalCone tight = merge_tight(a, b);
    const auto [axis, minimum] = brute_force_minimum(a, b);
    const long double tol = 1e-13L + 1e-13L * minimum;
    if (tight.saturated()) {
      ASSERT_GE(minimum + tol + kConeSlack, std::numbers::pi / 2) << "seed " << seed;
      continue;
    }
    ++compared;
    ASSERT_NEAR(static_cast<double>(tight.half_angle - kConeSlack), static_cast<double>(minimum),
                static_cast<double>(tol))
        << "seed " << seed << " scale " << scale;
    // No axis off the great circle does better: probe around the optimum at several scales.
    for (int k = 0; k < 6; ++k) {
      const long double eps = minimum * std::pow(10.0L, -k) + 1e-18L;
      const Vec3L dir = axis.cross(test::to_ld(rng.unit())).normalized();
      const Vec3L probe = (std::cos(eps) * axis + std::sin(eps) * dir).normalized();
      ASSERT_GE(needed(probe, a, b) + tol, minimum) << "seed " << seed << " probe " << k;
    }
  }
  EXPECT_GT(compared, kBruteCases / 2);
}

TEST(ConeMerge, SaturationIsMonotoneUpATree) {
  // Once a node saturates, every ancestor does; an unsaturated merge is never narrower than
  // either input.
  for (int seed = 0; seed < kCases; ++seed) {
    Rng rng(seed);
    const auto [a, b, scale] = test::random_cone_pair(rng);
    for (const ConeMerge policy : {ConeMerge::Provot, ConeMerge::Tight}) {
      const NormalCone m = merge_cones(a, b, policy);
      ASSERT_GE(m.half_angle, std::max(a.half_angle, b.half_angle)) << "seed " << seed;
      ASSERT_TRUE(merge_cones(saturated_cone(), a, policy).saturated());
      ASSERT_TRUE(merge_cones(b, saturated_cone(), policy).saturated());
    }
  }
}

}  // namespace
}  // namespace clothcd
