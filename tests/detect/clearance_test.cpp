// The corner clearance's cheap lower bound (triangle_corner_clearance_bound) against the exact
// clearance it stands in for: never above it, as computed, on random, sliver, far-off and
// degenerate moving triangles; close to it when the triangle barely deforms; and the fused
// bounds of the step and of its end equal the single ones.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "detect/clearance.hpp"

namespace clothcd::clearance_test {
namespace {

struct Moving {
  std::array<Eigen::Vector3d, 3> x0, x1;
  [[nodiscard]] std::array<const Eigen::Vector3d*, 3> at0() const {
    return {&x0[0], &x0[1], &x0[2]};
  }
  [[nodiscard]] std::array<const Eigen::Vector3d*, 3> at1() const {
    return {&x1[0], &x1[1], &x1[2]};
  }
};

Moving random_moving(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  auto vec = [&] { return Eigen::Vector3d(u(rng), u(rng), u(rng)); };
  const double size = std::pow(10.0, 6 * unit(rng) - 4);
  const Eigen::Vector3d origin = vec() * std::pow(10.0, 8 * unit(rng) - 4);
  const double motion = size * std::pow(10.0, 6 * unit(rng) - 5);
  Moving m;
  for (auto& p : m.x0)
    p = origin + size * vec();
  const int kind = static_cast<int>(4 * unit(rng));
  if (kind == 0) m.x0[2] = m.x0[0] + unit(rng) * (m.x0[1] - m.x0[0]) + 1e-9 * size * vec();
  if (kind == 1) m.x0[2] = m.x0[1];  // a zero-length side
  for (int i = 0; i < 3; ++i)
    m.x1[i] = m.x0[i] + motion * vec();
  if (kind == 2) m.x1 = m.x0;  // at rest
  return m;
}

TEST(CornerClearanceBound, NeverAboveTheExactClearance) {
  std::mt19937_64 rng(7);
  int settled = 0;
  for (int k = 0; k < 200000; ++k) {
    const Moving m = random_moving(rng);
    const double exact = detail::triangle_corner_clearance(m.at0(), m.at1());
    const double bound = detail::triangle_corner_clearance_bound(m.at0(), m.at1());
    if (std::isnan(bound)) continue;  // no extent: the exact clearance decides
    ASSERT_LE(bound, exact) << "case " << k;
    settled += bound > 0 ? 1 : 0;
  }
  EXPECT_GT(settled, 50000);  // the bound must be useful, not only safe
}

TEST(CornerClearanceBound, CloseToExactForNearlyRigidMotion) {
  // A right triangle with legs 1 and 2 translated by 1e-3: every corner keeps its height.
  Moving m;
  m.x0 = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(0, 1, 0)};
  for (int i = 0; i < 3; ++i)
    m.x1[i] = m.x0[i] + Eigen::Vector3d(1e-3, 0, 0);
  const double exact = detail::triangle_corner_clearance(m.at0(), m.at1());
  const double bound = detail::triangle_corner_clearance_bound(m.at0(), m.at1());
  EXPECT_NEAR(exact, 2 / std::sqrt(5.0), 1e-9);  // the height onto the hypotenuse
  EXPECT_LE(bound, exact);
  EXPECT_GT(bound, exact - 1e-9);
  // Coincident vertices: no bound (NaN), so the caller takes the exact clearance.
  m.x0 = {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1)};
  m.x1 = m.x0;
  EXPECT_TRUE(std::isnan(detail::triangle_corner_clearance_bound(m.at0(), m.at1())));
}

// The fused bounds the culling takes (the step's and its end's, one pass over the corners) are
// the single bounds bit for bit, NaN where those are NaN: the end's is never above the exact
// clearance at t1 either, since it is the step bound of a step without motion.
TEST(CornerClearanceBound, FusedBoundsEqualTheSingleOnes) {
  std::mt19937_64 rng(11);
  auto same = [](double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; };
  for (int k = 0; k < 100000; ++k) {
    const Moving m = random_moving(rng);
    const detail::CornerBounds b = detail::triangle_corner_clearance_bounds(m.at0(), m.at1());
    ASSERT_TRUE(same(b.step, detail::triangle_corner_clearance_bound(m.at0(), m.at1())))
        << "case " << k;
    ASSERT_TRUE(same(b.end, detail::triangle_corner_clearance_bound(m.at1(), m.at1())))
        << "case " << k;
    if (!std::isnan(b.end)) {
      ASSERT_LE(b.end, detail::triangle_corner_clearance(m.at1(), m.at1())) << "case " << k;
    }
  }
}

}  // namespace
}  // namespace clothcd::clearance_test
