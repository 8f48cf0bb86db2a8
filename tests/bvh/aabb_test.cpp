// The shared box operations: closed overlap, outward growth and outward rounding to float, and
// the node and feature boxes built on them.

#include "clothcd/bvh/aabb.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "clothcd/bvh/bvh.hpp"

namespace clothcd::aabb_test {
namespace {

TEST(Aabb, OverlapIsClosed) {
  const Aabb<double> a{{0, 0, 0}, {1, 1, 1}};
  Aabb<double> b{{1, 0.5, 0.5}, {2, 2, 2}};  // touches a's face x = 1
  EXPECT_TRUE(overlap(a, b));
  EXPECT_TRUE(overlap(b, a));
  b.lo[0] = std::nextafter(1.0, 2.0);
  EXPECT_FALSE(overlap(a, b));
  EXPECT_FALSE(overlap(b, a));
  BvhNode n, m;
  n.lo = a.lo;
  n.hi = a.hi;
  m.lo = {0.5, 1.0, -1.0};
  m.hi = {0.6, 3.0, 0.0};
  EXPECT_TRUE(overlap(n, m));
  m.lo[1] = std::nextafter(1.0, 2.0);
  EXPECT_FALSE(overlap(n, m));
}

// The node test (vectorized where the target allows) answers as the six scalar comparisons do,
// on touching, disjoint, crossed and NaN boxes alike.
TEST(Aabb, NodeOverlapMatchesTheScalarTest) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> pick(0, 9);
  const double nan = std::nan("");
  // Few distinct coordinates, so that boxes touch often.
  auto coord = [&] { return pick(rng) == 0 ? nan : 0.25 * pick(rng); };
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    BvhNode n, m;
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = coord();
      n.hi[k] = coord();
      m.lo[k] = coord();
      m.hi[k] = coord();
    }
    const bool expected = overlap(n.lo, n.hi, m.lo, m.hi);
    ASSERT_EQ(overlap(n, m), expected) << i;
    ASSERT_EQ(overlap(m, n), overlap(m.lo, m.hi, n.lo, n.hi)) << i;
    hits += expected ? 1 : 0;
  }
  EXPECT_GT(hits, 100);
  EXPECT_LT(hits, 19900);
}

TEST(Aabb, FeatureBoxesContainTheExactGrownBox) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coord(-1e3, 1e3), margin(0.0, 1e-2);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d p(coord(rng), coord(rng), coord(rng));
    const Eigen::Vector3d q = p + Eigen::Vector3d(coord(rng), coord(rng), coord(rng)) * 1e-3;
    const double h = i % 4 == 0 ? 0.0 : margin(rng);
    const FeatureBox b = swept_feature_box({&p, &q}, h);
    std::array<double, 3> lo{}, hi{};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(p[k], q[k]);
      hi[k] = std::max(p[k], q[k]);
    }
    inflate(lo, hi, h);
    for (int k = 0; k < 3; ++k) {
      // inflate: at least the margin away (the rounded sum, one ulp further out).
      EXPECT_LE(lo[k], std::min(p[k], q[k]) - h);
      EXPECT_GE(hi[k], std::max(p[k], q[k]) + h);
      // to float outwards: contains the double box, within one float step.
      EXPECT_LE(double(b.lo[k]), lo[k]);
      EXPECT_GE(double(b.hi[k]), hi[k]);
      EXPECT_GT(double(std::nextafter(b.lo[k], INFINITY)), lo[k]);
      EXPECT_LT(double(std::nextafter(b.hi[k], -INFINITY)), hi[k]);
    }
    EXPECT_EQ(to_feature_box(lo, hi), b);
  }
  // No margin: nothing grows.
  std::array<double, 3> lo{1, 2, 3}, hi{4, 5, 6};
  inflate(lo, hi, 0.0);
  EXPECT_EQ(lo, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(hi, (std::array<double, 3>{4, 5, 6}));
}

}  // namespace
}  // namespace clothcd::aabb_test
