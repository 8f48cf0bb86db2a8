// The vector NP filter against the scalar one, lane by lane, on every instruction set this CPU
// runs: random queries over the whole range of scales (both ends of the filter's validity range
// included), exactly and nearly coplanar motions (coefficients at the error bound), and
// non-finite, zero and subnormal coordinates. Every query the vector filter culls is also checked
// against the exact (GMP) oracle: it has no contact.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "ccd/cubic.hpp"
#include "ccd/np_batch.hpp"
#include "exact_oracle.hpp"

namespace clothcd {
namespace {

using ccd_detail::Kind;
using ccd_detail::NpBlock;
using ccd_detail::NpIsa;
using V = Eigen::Vector3d;
using Points = std::array<V, 8>;

struct Gen {
  std::mt19937_64 rng;
  explicit Gen(std::uint64_t seed) : rng(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(rng); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<>(lo, hi)(rng); }
  V vec(double s) { return V(uniform(-s, s), uniform(-s, s), uniform(-s, s)); }
};

// A query of one of several families; `family` picks it.
Points make_query(Gen& g, int family) {
  Points p;
  switch (family) {
    case 0: {  // generic, scales across (and past) the range [2^-300, 2^100] of the filter
      const double s = std::ldexp(1.0, g.integer(-330, 120));
      const V shift = g.vec(4 * s);
      for (V& x : p)
        x = shift + g.vec(s);
      break;
    }
    case 1: {  // four points in one moving plane (exactly coplanar on a grid, both times)
      for (int t = 0; t < 2; ++t) {
        const V o = g.vec(8).array().round(), a = g.vec(4).array().round(),
                b = g.vec(4).array().round();
        for (int k = 0; k < 4; ++k)
          p[4 * t + k] = o + g.integer(-3, 3) * a + g.integer(-3, 3) * b;
      }
      break;
    }
    case 2: {  // nearly coplanar: a planar configuration pushed off the plane by a few ulps
      const double s = std::ldexp(1.0, g.integer(-40, 40));
      const V o = g.vec(s), a = g.vec(s), b = g.vec(s), n = a.cross(b).normalized();
      for (int k = 0; k < 8; ++k) {
        const double off = g.integer(-4, 4) * std::ldexp(s, -50);
        p[k] = o + g.uniform(-1, 1) * a + g.uniform(-1, 1) * b + off * n;
      }
      break;
    }
    case 3: {  // special coordinates: zeros, subnormals, infinities, NaN, huge values
      const double specials[] = {0.0,
                                 -0.0,
                                 std::numeric_limits<double>::denorm_min(),
                                 -3 * std::numeric_limits<double>::denorm_min(),
                                 std::numeric_limits<double>::min(),
                                 std::numeric_limits<double>::infinity(),
                                 -std::numeric_limits<double>::infinity(),
                                 std::numeric_limits<double>::quiet_NaN(),
                                 0x1p100,
                                 -0x1p100,
                                 0x1p-300,
                                 std::numeric_limits<double>::max()};
      for (V& x : p) {
        x = g.vec(1);
        for (int c = 0; c < 3; ++c) {
          if (g.integer(0, 3) == 0) x[c] = specials[g.integer(0, std::size(specials) - 1)];
        }
      }
      break;
    }
    default: {  // small moving triangle and point far apart or crossing: culled and kept mixed
      const V shift = g.vec(1);
      for (int k = 0; k < 4; ++k) {
        p[k] = shift + g.vec(0.1);
        p[k + 4] = p[k] + g.vec(0.05);
      }
      break;
    }
  }
  return p;
}

bool scalar_culls(Kind kind, const Points& p) {
  std::array<const V*, 8> ptr;
  for (int k = 0; k < 8; ++k)
    ptr[k] = &p[k];
  return ccd_detail::unscaled_np_filter(kind, ptr) == ccd_detail::NpVerdict::culled;
}

bool exact_contact(Kind kind, const Points& p) {
  if (kind == Kind::vertex_face) {
    return test::exact_vertex_face_contact({p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]});
  }
  return test::exact_edge_edge_contact({p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]});
}

TEST(NpBatch, VectorVerdictsAreTheScalarOnes) {
  const NpIsa isas[] = {NpIsa::best, NpIsa::sse2, NpIsa::avx2, NpIsa::avx512};
  std::uint64_t culled_total = 0, compared = 0;
  for (const NpIsa isa : isas) {
    if (!ccd_detail::np_isa_available(isa)) continue;
    for (const Kind kind : {Kind::vertex_face, Kind::edge_edge}) {
      for (std::uint64_t seed = 1; seed <= 40; ++seed) {
        Gen g(seed * 7919 + static_cast<int>(isa) * 31 + static_cast<int>(kind));
        NpBlock b;
        // Block sizes that are not multiples of the vector width, too.
        b.n = seed % 5 == 0 ? static_cast<int>(seed % NpBlock::kSize) : NpBlock::kSize;
        std::vector<Points> qs(b.n);
        for (int i = 0; i < b.n; ++i) {
          qs[i] = make_query(g, g.integer(0, 4));
          for (int k = 0; k < 8; ++k) {
            for (int c = 0; c < 3; ++c)
              b.x[k][c][i] = qs[i][k][c];
          }
        }
        std::array<std::uint8_t, NpBlock::kSize> culled{};
        ccd_detail::np_filter_block(kind, b, culled.data(), isa);
        for (int i = 0; i < b.n; ++i) {
          ++compared;
          const bool scalar = scalar_culls(kind, qs[i]);
          ASSERT_EQ(culled[i] != 0, scalar)
              << "isa " << static_cast<int>(isa) << " kind " << static_cast<int>(kind) << " seed "
              << seed << " lane " << i;
          if (culled[i] != 0 && qs[i][0].allFinite() && g.integer(0, 3) == 0) {
            // A cull is a proof of no contact: the exact oracle agrees (a sample, for time).
            ASSERT_FALSE(exact_contact(kind, qs[i])) << "seed " << seed << " lane " << i;
          }
          culled_total += culled[i];
        }
      }
    }
  }
  // Both verdicts occur, so the comparison is not vacuous.
  EXPECT_GT(culled_total, 0u);
  EXPECT_LT(culled_total, compared);
}

}  // namespace
}  // namespace clothcd
