// The contour tests of sound culling (src/detect/contour.hpp): the star-shaped test and the general
// simplicity test. Loops that wind twice or cross must fail both; simple loops that are not
// star-shaped must pass the simplicity test; on random moving polygons every accepted loop must be
// simple at every sampled time.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "detect/contour.hpp"

namespace clothcd::detail {
namespace {

using V = Eigen::Vector3d;
const V kZ = V::UnitZ();

std::vector<int> iota_loop(int n) {
  std::vector<int> l(n);
  for (int i = 0; i < n; ++i)
    l[i] = i;
  return l;
}

// Proper crossing or touching of 2-D segments (x, y only), with exact-sign orientation.
double orient2(const V& a, const V& b, const V& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}
bool segments_meet(const V& p, const V& q, const V& r, const V& s) {
  const double o1 = orient2(r, s, p), o2 = orient2(r, s, q), o3 = orient2(p, q, r),
               o4 = orient2(p, q, s);
  return o1 * o2 <= 0 && o3 * o4 <= 0;
}
// Brute force: no two non-consecutive edges of the polygon meet (at one instant).
bool simple_at(const std::vector<V>& p) {
  const int n = static_cast<int>(p.size());
  for (int i = 0; i < n; ++i) {
    for (int j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;
      if (segments_meet(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return false;
    }
  }
  return true;
}

TEST(Contour, BranchedFanWindingTwiceFailsBoth) {
  // The rim of a fan winding twice around its centre (two 4-triangle turns, radius growing so the
  // projected rim is a spiral that crosses itself when it closes); normals stay near +z.
  std::vector<V> rim;
  for (int k = 0; k < 8; ++k) {
    const double a = k * std::numbers::pi / 2, r = 1.0 + 0.1 * k;
    rim.emplace_back(r * std::cos(a), r * std::sin(a), 0.01 * std::min(k, 8 - k));
  }
  const auto loop = iota_loop(8);
  EXPECT_FALSE(contour_star_shaped(loop, rim, rim, kZ));
  EXPECT_FALSE(contour_simple(loop, rim, rim, kZ));
}

TEST(Contour, SimpleUShapeIsNotStarButSimple) {
  // A counter-clockwise U (its mean lies in the notch): simple, not star-shaped about the mean.
  const std::vector<V> u{{0, 0, 0}, {3, 0, 0}, {3, 3, 0}, {2, 3, 0},
                         {2, 1, 0}, {1, 1, 0}, {1, 3, 0}, {0, 3, 0}};
  const auto loop = iota_loop(8);
  EXPECT_FALSE(contour_star_shaped(loop, u, u, kZ));
  EXPECT_TRUE(contour_simple(loop, u, u, kZ));
  // Moving rigidly (a rotation about the axis and a translation) keeps it simple.
  std::vector<V> moved;
  const Eigen::AngleAxisd rot(0.3, kZ);
  for (const V& p : u)
    moved.push_back(rot * p + V(0.5, -0.2, 0.7));
  EXPECT_TRUE(contour_simple(loop, u, moved, kZ));
  // Clockwise (the patch seen from below): negative area, rejected.
  std::vector<int> reversed(loop.rbegin(), loop.rend());
  EXPECT_FALSE(contour_simple(reversed, u, u, kZ));
  // The inner top corners (vertices 3 and 6) move left through the left arm: at t = 1 the loop
  // crosses itself, so it is rejected.
  std::vector<V> crossing = u;
  crossing[6] = V(-1, 3, 0);
  crossing[3] = V(-0.5, 3, 0);
  EXPECT_FALSE(contour_simple(loop, u, crossing, kZ));
}

TEST(Contour, AcceptedRandomMovingPolygonsAreSimpleThroughout) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  int accepted = 0, rejected = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 5 + static_cast<int>(rng() % 12);
    const double noise = 0.15 + 0.6 * (trial % 4) / 3.0;
    const double motion = 0.05 + 0.5 * ((trial / 4) % 4) / 3.0;
    std::vector<V> p0(n), p1(n);
    for (int i = 0; i < n; ++i) {
      const double a = 2 * std::numbers::pi * i / n;
      const double r = 1.0 + noise * uni(rng);
      p0[i] = V(r * std::cos(a), r * std::sin(a), 0.1 * uni(rng));
      p1[i] = p0[i] + motion * V(uni(rng), uni(rng), uni(rng));
    }
    const auto loop = iota_loop(n);
    if (!contour_simple(loop, p0, p1, kZ)) {
      ++rejected;
      continue;
    }
    ++accepted;
    for (int s = 0; s <= 200; ++s) {
      const double t = s / 200.0;
      std::vector<V> pt(n);
      for (int i = 0; i < n; ++i)
        pt[i] = (1 - t) * p0[i] + t * p1[i];
      ASSERT_TRUE(simple_at(pt)) << "trial " << trial << " t " << t;
    }
  }
  // Both outcomes occur, so the test exercises the predicate.
  EXPECT_GT(accepted, 100);
  EXPECT_GT(rejected, 100);
}

}  // namespace
}  // namespace clothcd::detail
