// The page's positions: 16-bit values over the sequence's box, stored as zigzag-coded differences
// from a straight-line guess modulo 2^16, decode to within half a quantum of every input position,
// also across jumps that wrap.
#include "view/quantize.hpp"

#include <gtest/gtest.h>

#include <random>

namespace clothcd::view::detail {
namespace {

TEST(ViewQuantize, DecodesWithinHalfAStepOfEveryFrame) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 50;
  std::vector<std::vector<Vec3>> frames(6, std::vector<Vec3>(n));
  for (int v = 0; v < n; ++v)
    frames[0][v] = Vec3(u(rng), 2.0 + u(rng), 0.01 * u(rng));
  for (std::size_t k = 1; k < frames.size(); ++k) {
    for (int v = 0; v < n; ++v)
      frames[k][v] = frames[k - 1][v] + Vec3(0.001 * u(rng), 0.001 * u(rng), 0.0);
  }
  frames[3][7] = Vec3(5.0, -3.0, 0.0);  // a jump across the whole box and back
  const QuantizedFrames q = quantize_frames(frames);
  ASSERT_EQ(q.low.size(), frames.size() * n * 3);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    for (int v = 0; v < n; ++v) {
      const Vec3 d = decoded_position(q, n, static_cast<int>(k), v) - frames[k][v];
      for (int a = 0; a < 3; ++a)
        EXPECT_LE(std::abs(d[a]), 0.5 * q.step[a] * (1 + 1e-9)) << k << " " << v << " " << a;
    }
  }
  // Small motions: nearly all high bytes of the later frames are 0 (what makes the differences
  // compress).
  std::size_t flat = 0, later = 0;
  for (std::size_t i = n * 3; i < q.high.size(); ++i, ++later)
    flat += q.high[i] == 0;
  EXPECT_GT(flat, later * 9 / 10);
}

// An axis of zero extent (a flat sheet) decodes exactly; the box's ends decode to them.
TEST(ViewQuantize, AFlatAxisAndTheBoxEndsDecodeExactly) {
  std::vector<std::vector<Vec3>> frames{{Vec3(1, 2, 3), Vec3(4, 2, 3)},
                                        {Vec3(1, 2, 3), Vec3(1, 2, 3)}};
  const QuantizedFrames q = quantize_frames(frames);
  for (int k = 0; k < 2; ++k) {
    for (int v = 0; v < 2; ++v) {
      const Vec3 p = decoded_position(q, 2, k, v);
      EXPECT_NEAR(p.x(), frames[k][v].x(), 1e-12);
      EXPECT_EQ(p.y(), 2.0);
      EXPECT_EQ(p.z(), 3.0);
    }
  }
}

}  // namespace
}  // namespace clothcd::view::detail
