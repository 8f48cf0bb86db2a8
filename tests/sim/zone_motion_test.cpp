// The rigid motion of an impact zone: it reproduces rigid fields, and for any field it keeps the
// zone's linear and angular momentum (what a free zone must conserve, Provot 1997).
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace clothcd::sim::detail
