// Property tests of the optimal cone (docs/algorithms.md 4): minimal against a brute-force search
// over every pair and triple, never wider than a hierarchical merge, saturated exactly when the set
// spans a hemisphere, and deterministic.
#include <gtest/gtest.h>

#include <iomanip>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
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

// ---------------------------------------------------------------------------------------------
// Degenerate families at every size: the shapes cloth normals take (flat patches repeat one
// direction, cylinders put them on a great circle, folds and crumples span a hemisphere).

enum class Family {
  Random,          // uniform in a cap of the given radius
  Equal,           // one direction repeated, at random lengths
  Antipodal,       // a random set plus an antiparallel pair: saturated
  ArcOfCircle,     // on a great-circle arc shorter than pi: the diametral cap of its ends
  FullCircle,      // spread over more than half a great circle: saturated
  NearHemisphere,  // pi/2 - margin from a pole, all around it
  Clustered,       // two to four clusters of spread 1e-12 rad
  Tiny,            // uniform in a cap of radius 1e-12 rad
  CoCircular,      // mostly on the rim of a cap, some inside
};
constexpr Family kFamilies[] = {Family::Random,      Family::Equal,      Family::Antipodal,
                                Family::ArcOfCircle, Family::FullCircle, Family::NearHemisphere,
                                Family::Clustered,   Family::Tiny,       Family::CoCircular};

// Whether a set of the family of that size has no cone below pi/2.
bool saturates(Family f, int n) {
  return (f == Family::Antipodal && n >= 2) || (f == Family::FullCircle && n >= 3);
}

std::vector<Eigen::Vector3d> family_set(Family f, Rng& rng, int n) {
  const Eigen::Vector3d c = rng.unit();
  const Eigen::Vector3d e = rng.perpendicular(c);
  const double scale = rng.log_uniform(1e-12, 1.5);
  std::vector<Eigen::Vector3d> v;
  auto in_cap = [&](const Eigen::Vector3d& centre, double radius) {
    return test::rotate(centre, rng.perpendicular(centre), radius * std::sqrt(rng.uniform()));
  };
  // On the great circle through c along e, at signed angle t from c.
  auto on_circle = [&](long double t) { return test::rotate(c, e, t); };
  switch (f) {
    case Family::Random:
      for (int i = 0; i < n; ++i)
        v.push_back(in_cap(c, scale));
      break;
    case Family::Equal:
      for (int i = 0; i < n; ++i)
        v.push_back(c * (i == 0 ? 1.0 : rng.log_uniform(1e-3, 1e3)));
      break;
    case Family::Antipodal:
      for (int i = 0; i + 2 < n; ++i)
        v.push_back(in_cap(c, scale));
      v.insert(v.begin() + rng.integer(0, static_cast<int>(v.size())), c);
      v.insert(v.begin() + rng.integer(0, static_cast<int>(v.size())), -c);
      break;
    case Family::ArcOfCircle: {
      const double half = std::min(scale, 1.5);
      for (int i = 0; i < n; ++i)
        v.push_back(on_circle(i < 2 ? (i == 0 ? -half : half) : rng.uniform(-half, half)));
      std::swap(v[0], v[rng.integer(0, n - 1)]);
      break;
    }
    case Family::FullCircle:
      // Both ends and the middle pin the set to more than a half circle.
      for (int i = 0; i < n; ++i) {
        const long double t = i < 3 ? (i - 1) * 0.6L * std::numbers::pi_v<long double>
                                    : rng.uniform(-0.6, 0.6) * std::numbers::pi;
        v.push_back(on_circle(t));
      }
      for (int i = 0; i < n; ++i)
        std::swap(v[i], v[rng.integer(i, n - 1)]);
      break;
    case Family::NearHemisphere: {
      const double margin = rng.log_uniform(1e-6, 1e-2);
      for (int i = 0; i < n; ++i)
        v.push_back(test::rotate(c, rng.perpendicular(c), std::numbers::pi / 2 - margin));
      break;
    }
    case Family::Clustered: {
      std::vector<Eigen::Vector3d> centres;
      for (int k = rng.integer(2, 4); k > 0; --k)
        centres.push_back(in_cap(c, scale));
      for (int i = 0; i < n; ++i)
        v.push_back(in_cap(centres[rng.integer(0, static_cast<int>(centres.size()) - 1)], 1e-12));
      break;
    }
    case Family::Tiny:
      for (int i = 0; i < n; ++i)
        v.push_back(in_cap(c, 1e-12));
      break;
    case Family::CoCircular:
      for (int i = 0; i < n; ++i) {
        const double t = rng.chance(0.8) ? scale : scale * std::sqrt(rng.uniform());
        v.push_back(test::rotate(c, rng.perpendicular(c), t));
      }
      break;
  }
  if (n == 1 && v.size() > 1) v.resize(1);
  return v;
}

// The angle from `axis` to `p` in long double, with the cross product taken as a x (p - a), so
// it keeps full relative precision at 1e-12 rad.
long double angle_precise(const Eigen::Vector3d& axis, const Eigen::Vector3d& p) {
  const Vec3L a = to_ld(axis), q = to_ld(p).normalized();
  return std::atan2(a.cross(q - a).norm(), a.dot(q));
}

long double needed_precise(const Eigen::Vector3d& axis, const std::vector<Eigen::Vector3d>& v) {
  long double worst = 0;
  for (const auto& p : v)
    worst = std::max(worst, angle_precise(axis, p));
  return worst;
}

// Optimality certificate of a cap (the minimal cap's optimality condition): the directions from
// the axis toward the rim points (those within 1e-8 of the largest angle, or 1e-14 rad) leave no
// gap above pi around the axis; otherwise moving the axis into the gap would shrink every rim
// angle.
bool certified_minimal(const Eigen::Vector3d& axis, const std::vector<Eigen::Vector3d>& v) {
  const long double theta = needed_precise(axis, v);
  if (theta < 1e-14L) return true;  // the oracles' absolute tolerance
  const Vec3L a = to_ld(axis);
  const Vec3L u = a.unitOrthogonal(), w = a.cross(u);
  std::vector<long double> phi;
  for (const auto& p : v) {
    if (angle_precise(axis, p) < theta * (1 - 1e-8L) - 1e-14L) continue;
    const Vec3L q = to_ld(p).normalized();
    const Vec3L t = a.cross(q - a);  // the tangent toward p, turned by 90 degrees about a
    phi.push_back(std::atan2(t.dot(w), t.dot(u)));
  }
  std::sort(phi.begin(), phi.end());
  long double gap = phi.front() + 2 * std::numbers::pi_v<long double> - phi.back();
  for (std::size_t i = 1; i < phi.size(); ++i)
    gap = std::max(gap, phi[i] - phi[i - 1]);
  // An axis off by the 1e-14 rad of the oracles' tolerance turns the rim directions by 1e-14 /
  // theta.
  return gap <= std::numbers::pi_v<long double> + 1e-6L + 1e-14L / theta;
}

TEST(OptimalCone, DegenerateFamiliesMatchBruteForce) {
  for (const Family f : kFamilies) {
    for (int seed = 0; seed < kCases / 250; ++seed) {
      Rng rng(seed);
      const int n = rng.integer(1, 9);
      const auto set = family_set(f, rng, n);
      const NormalCone c = optimal_cone(set);
      const auto pts = unit_ld(set);
      // Spread of the set, for the choice of oracle.
      long double spread = 0;
      for (const auto& p : pts)
        spread = std::max(spread, angle_ld(pts[0], p));
      const long double brute =
          spread > 2e-5L ? brute_force_spherical(pts) : brute_force_planar(pts);
      const auto trace = ::testing::Message() << std::setprecision(17) << "family " << int(f)
                                              << " seed " << seed << " n " << n;
      if (c.saturated()) {
        ASSERT_GE(brute, std::numbers::pi / 2 - 1e-9) << trace;
        continue;
      }
      ASSERT_LE(needed_precise(c.axis, set), c.half_angle) << trace;  // containment
      ASSERT_NEAR(static_cast<double>(c.half_angle - kConeSlack), static_cast<double>(brute),
                  static_cast<double>(1e-14L + 2e-9L * brute))
          << trace;
    }
  }
}

TEST(OptimalCone, DegenerateFamiliesAtEverySizeAreContainedAndOptimal) {
  for (const Family f : kFamilies) {
    for (const int n : {1, 2, 3, 4, 7, 30, 300, 2000}) {
      for (int seed = 0; seed < 12; ++seed) {
        Rng rng(1000 * n + seed);
        const auto set = family_set(f, rng, n);
        const NormalCone c = optimal_cone(set);
        const auto trace = ::testing::Message() << std::setprecision(17) << "family " << int(f)
                                                << " seed " << seed << " n " << n;
        const NormalCone again = optimal_cone(set);
        ASSERT_EQ(c.axis, again.axis) << trace;
        ASSERT_EQ(c.half_angle, again.half_angle) << trace;
        if (saturates(f, n)) {
          ASSERT_TRUE(c.saturated()) << trace;
          continue;
        }
        ASSERT_FALSE(c.saturated()) << trace;
        ASSERT_LE(needed_precise(c.axis, set), c.half_angle) << trace;
        ASSERT_TRUE(certified_minimal(c.axis, set)) << trace;
        // The certificate has teeth: an axis moved by a thousandth of the angle fails it.
        if (c.half_angle > 1e-9) {
          const Eigen::Vector3d moved =
              test::rotate(c.axis, rng.perpendicular(c.axis), 1e-3 * c.half_angle);
          ASSERT_FALSE(certified_minimal(moved, set)) << trace;
        }
      }
    }
  }
}

// Random partitions of a set, with the parts' optimal cones or with cones that are wrong: the
// hints change the search, never the cone (beyond rounding) nor containment.
TEST(OptimalCone, PartsOnlyOrderTheSearch) {
  for (int seed = 0; seed < 400; ++seed) {
    Rng rng(seed);
    const Family f = kFamilies[rng.integer(0, std::size(kFamilies) - 1)];
    const int n = rng.integer(1, 600);
    const auto set = family_set(f, rng, n);
    const NormalCone plain = optimal_cone(set);
    std::vector<ConePart> parts;
    const bool wrong = rng.chance(0.3);
    for (std::size_t begin = 0; begin < set.size();) {
      const std::size_t count =
          std::min<std::size_t>(set.size() - begin, rng.integer(1, 1 + n / 2));
      const std::span<const Eigen::Vector3d> part(set.data() + begin, count);
      parts.push_back(
          {count, wrong ? NormalCone{rng.unit(), rng.uniform(0.0, 2.0)} : optimal_cone(part)});
      begin += count;
    }
    const NormalCone hinted = optimal_cone(set, parts);
    const auto trace = ::testing::Message() << std::setprecision(17) << "family " << int(f)
                                            << " seed " << seed << " n " << n;
    ASSERT_EQ(hinted.saturated(), plain.saturated()) << trace;
    if (plain.saturated()) continue;
    ASSERT_LE(needed_precise(hinted.axis, set), hinted.half_angle) << trace;
    // The tolerance of the brute-force comparisons: the search's containment test lets points in
    // up to 1e-14 rad (a hundredth of kConeSlack).
    ASSERT_NEAR(hinted.half_angle, plain.half_angle, 1e-14 + 1e-11 * plain.half_angle) << trace;
  }
  const std::vector<Eigen::Vector3d> set(5, Eigen::Vector3d::UnitZ());
  const std::vector<ConePart> short_parts = {{2, {}}, {2, {}}};
  EXPECT_THROW((void)optimal_cone(set, short_parts), std::invalid_argument);
}

}  // namespace
}  // namespace clothcd
