// overlap() of two feature boxes (the narrow phase's box test, SSE on x86-64) against the scalar
// six comparisons: the same answer on random boxes, touching boxes, signed zeros, infinities and
// NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "clothcd/bvh/aabb.hpp"

namespace clothcd::box_overlap_test {
namespace {

float pick(std::mt19937& rng) {
  static const float special[] = {0.0f,
                                  -0.0f,
                                  1.0f,
                                  -1.0f,
                                  std::numeric_limits<float>::infinity(),
                                  -std::numeric_limits<float>::infinity(),
                                  std::numeric_limits<float>::quiet_NaN(),
                                  std::numeric_limits<float>::denorm_min()};
  std::uniform_int_distribution<int> kind(0, 9);
  const int k = kind(rng);
  if (k < 8 && std::uniform_int_distribution<int>(0, 3)(rng) == 0) return special[k];
  // Small integers collide often: touching and equal faces.
  return static_cast<float>(std::uniform_int_distribution<int>(-3, 3)(rng));
}

TEST(BoxOverlap, MatchesTheScalarTest) {
  std::mt19937 rng(7);
  int hits = 0, misses = 0;
  for (int i = 0; i < 200000; ++i) {
    FeatureBox a, b;
    for (int k = 0; k < 3; ++k) {
      a.lo[k] = pick(rng);
      a.hi[k] = pick(rng);
      b.lo[k] = pick(rng);
      b.hi[k] = pick(rng);
      if (std::uniform_int_distribution<int>(0, 1)(rng) == 0) {  // mostly well-formed boxes
        if (a.hi[k] < a.lo[k]) std::swap(a.lo[k], a.hi[k]);
        if (b.hi[k] < b.lo[k]) std::swap(b.lo[k], b.hi[k]);
      }
    }
    const bool expect = overlap(a.lo, a.hi, b.lo, b.hi);
    ASSERT_EQ(overlap(a, b), expect) << i;
    ASSERT_EQ(overlap(b, a), overlap(b.lo, b.hi, a.lo, a.hi)) << i;
    (expect ? hits : misses)++;
  }
  EXPECT_GT(hits, 1000);
  EXPECT_GT(misses, 1000);
}

TEST(BoxOverlap, BoxesInAnArray) {
  // Boxes side by side, the last one at the end of its array: the test reads within each box.
  std::vector<FeatureBox> boxes(3);
  boxes[0] = {{0, 0, 0}, {1, 1, 1}};
  boxes[1] = {{1, 1, 1}, {2, 2, 2}};
  boxes[2] = {{2.5f, 0, 0}, {3, 1, 1}};
  EXPECT_TRUE(overlap(boxes[0], boxes[1]));
  EXPECT_FALSE(overlap(boxes[0], boxes[2]));
  EXPECT_FALSE(overlap(boxes[2], boxes[1]));
  EXPECT_TRUE(overlap(boxes[2], boxes[2]));
}

}  // namespace
}  // namespace clothcd::box_overlap_test
