// The motion of an impact zone. The rigid one reproduces rigid fields, and for any field it keeps
// the zone's linear and angular momentum (what a free zone must conserve, Provot 1997). The affine
// one reproduces affine fields and declines flat point sets and motions that strain too much.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>
#include <vector>

#include "sim/zone_motion.hpp"

namespace clothcd::sim::detail {
namespace {

struct Points {
  std::vector<Vec3> x, v;
  std::vector<double> w;
};

// n random points in a box of the given half-extents, with velocities field(x) and random weights.
template <typename Field>
Points sample(int n, const Vec3& extent, Field field, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Points p;
  for (int i = 0; i < n; ++i) {
    const Vec3 x(extent.x() * u(rng), extent.y() * u(rng), extent.z() * u(rng));
    p.x.push_back(x + Vec3(0.3, 1.1, -0.2));
    p.v.push_back(field(p.x.back()));
    p.w.push_back(0.5 + 0.25 * (u(rng) + 1.0));
  }
  return p;
}

const Vec3 kOmega(0.4, -1.3, 2.0), kV(0.2, -0.5, 0.1), kC(0.1, 0.9, 0.0);

TEST(ZoneMotion, RigidFitReproducesARigidField) {
  const Points p = sample(
      40, Vec3(0.1, 0.05, 0.08), [](const Vec3& x) { return Vec3(kV + kOmega.cross(x - kC)); }, 1);
  const RigidMotion m = fit_rigid(p.x, p.v, p.w);
  for (std::size_t i = 0; i < p.x.size(); ++i)
    EXPECT_LT((m.at(p.x[i]) - p.v[i]).norm(), 1e-12) << i;
  EXPECT_LT((m.omega - kOmega).norm(), 1e-10);
}

TEST(ZoneMotion, RigidFitKeepsMomentumAndAngularMomentum) {
  // A field no rigid motion follows (stretch, shear and noise).
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.3);
  const Points p = sample(
      50, Vec3(0.1, 0.05, 0.08),
      [&](const Vec3& x) {
        return Vec3(kV + Vec3(0.8 * x.x() + 0.1 * x.y(), -0.3 * x.y(), 0.4 * x.z()) +
                    Vec3(noise(rng), noise(rng), noise(rng)));
      },
      2);
  const RigidMotion m = fit_rigid(p.x, p.v, p.w);
  Vec3 dp = Vec3::Zero(), dl = Vec3::Zero(), scale = Vec3::Zero();
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    const Vec3 r = p.v[i] - m.at(p.x[i]);
    dp += p.w[i] * r;
    dl += p.w[i] * (p.x[i] - m.xc).cross(r);
    scale += p.w[i] * p.v[i].cwiseAbs();
  }
  EXPECT_LT(dp.norm(), 1e-12 * scale.norm());
  EXPECT_LT(dl.norm(), 1e-12 * scale.norm());
}

TEST(ZoneMotion, CollinearPointsGetNoSpinAboutTheirLine) {
  // Points on a line along x fix no rotation about x: the fit leaves it at zero and still
  // matches a field spinning about an axis across the line.
  const Vec3 omega(0.0, 1.5, -0.7);
  Points p;
  for (int i = 0; i < 10; ++i) {
    p.x.emplace_back(0.01 * i, 0.5, 0.2);
    p.v.push_back(kV + omega.cross(p.x.back() - kC));
    p.w.push_back(1.0 + 0.1 * i);
  }
  const RigidMotion m = fit_rigid(p.x, p.v, p.w);
  EXPECT_NEAR(m.omega.x(), 0.0, 1e-12);
  for (std::size_t i = 0; i < p.x.size(); ++i)
    EXPECT_LT((m.at(p.x[i]) - p.v[i]).norm(), 1e-12) << i;
  // One point, or none: the mean velocity, no spin.
  const RigidMotion one = fit_rigid({p.x[3]}, {p.v[3]}, {2.0});
  EXPECT_EQ(one.vc, p.v[3]);
  EXPECT_EQ(one.omega, Vec3::Zero());
  EXPECT_EQ(fit_rigid({}, {}, {}).vc, Vec3::Zero());
}

// A shear and stretch no rigid motion follows, small enough for a substep of 1 ms.
const Eigen::Matrix3d kA =
    (Eigen::Matrix3d() << 0.0, 30.0, 5.0, 30.0, -20.0, 0.0, -10.0, 8.0, 40.0).finished();

TEST(ZoneMotion, AffineFitReproducesAnAffineField) {
  const Points p = sample(
      30, Vec3(0.1, 0.05, 0.08), [](const Vec3& x) { return Vec3(kV + kA * (x - kC)); }, 3);
  const std::optional<AffineMotion> m = fit_affine(p.x, p.v, p.w, 1e-3);
  ASSERT_TRUE(m.has_value());
  for (std::size_t i = 0; i < p.x.size(); ++i)
    EXPECT_LT((m->at(p.x[i]) - p.v[i]).norm(), 1e-10) << i;
  EXPECT_LT((m->a - kA).norm(), 1e-8);
  // The rigid fit of the same field misses it by far more: what the affine motion is for.
  const RigidMotion r = fit_rigid(p.x, p.v, p.w);
  double miss = 0.0;
  for (std::size_t i = 0; i < p.x.size(); ++i)
    miss = std::max(miss, (r.at(p.x[i]) - p.v[i]).norm());
  EXPECT_GT(miss, 0.5);
}

TEST(ZoneMotion, AffineFitLeavesTheNoiseOrthogonalToEveryAffineField) {
  // Least squares: the residual has zero weighted sum and zero weighted moments (sum w r d^T).
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.05);
  const Points p = sample(
      40, Vec3(0.1, 0.05, 0.08),
      [&](const Vec3& x) {
        return Vec3(kV + kA * (x - kC) + Vec3(noise(rng), noise(rng), noise(rng)));
      },
      4);
  const std::optional<AffineMotion> m = fit_affine(p.x, p.v, p.w, 1e-3);
  ASSERT_TRUE(m.has_value());
  Vec3 sum = Vec3::Zero();
  Eigen::Matrix3d moments = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    const Vec3 r = p.v[i] - m->at(p.x[i]);
    sum += p.w[i] * r;
    moments += p.w[i] * r * (p.x[i] - m->xc).transpose();
  }
  EXPECT_LT(sum.norm(), 1e-12);
  EXPECT_LT(moments.norm(), 1e-12);
}

TEST(ZoneMotion, AffineFitDeclinesFlatPointsAndLargeStrains) {
  const auto field = [](const Vec3& x) { return Vec3(kV + kA * (x - kC)); };
  // Points 0.5 mm either side of a plane 10 cm across: too flat to fix the gradient across it.
  const Points flat = sample(30, Vec3(0.1, 0.0005, 0.08), field, 5);
  EXPECT_FALSE(fit_affine(flat.x, flat.v, flat.w, 1e-3).has_value());
  // 2 mm either side is thick enough.
  const Points thick = sample(30, Vec3(0.1, 0.002, 0.08), field, 5);
  EXPECT_TRUE(fit_affine(thick.x, thick.v, thick.w, 1e-3).has_value());
  // The same field over a substep 10 times longer strains the zone by |h A| > 0.2.
  EXPECT_FALSE(fit_affine(thick.x, thick.v, thick.w, 1e-2).has_value());
  EXPECT_TRUE(fit_affine(thick.x, thick.v, thick.w, 1e-2, {.max_strain = 1.0}).has_value());
  // Fewer than 4 points, or no weight: nothing.
  EXPECT_FALSE(fit_affine({kC, kV, kOmega}, {kV, kV, kV}, {1.0, 1.0, 1.0}, 1e-3).has_value());
  EXPECT_FALSE(fit_affine(thick.x, thick.v, std::vector<double>(30, 0.0), 1e-3).has_value());
}

}  // namespace
}  // namespace clothcd::sim::detail
