// The batched whole-triangle distance filter (SSE2, AVX2, AVX-512 and the dispatching entry)
// against the scalar filter, triangles_filter_culls: the same verdict and the same bound at t1,
// bit for bit, for every pair of seeded random families (generic over many scales, resting
// layers near the threshold, degenerate and needle triangles, overflowing magnitudes, non-finite
// coordinates) and for every batch size. The scalar filter itself against the Eigen formulation
// it replaced (written out below), bit for bit on finite input, and against the definition of a
// lower bound: no pair of points of the two triangles is closer. Likewise the static bound
// (triangle_bound_batch) against triangle_triangle_bound.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "ccd/face_batch.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "support/isa_paths.hpp"
#include "support/random_gen.hpp"

namespace clothcd::face_batch_test {
namespace {

using V = Eigen::Vector3d;
using ccd_detail::FacePairBatch;
using test::Gen;

// Corners of a at t0, a at t1, b at t0, b at t1.
using Pair = std::array<V, 12>;

Pair make_pair(Gen& g, int family) {
  Pair p;
  switch (family) {
    case 0: {  // generic, log-uniform scale
      const double s = std::ldexp(1.0, g.integer(-40, 40));
      for (auto& x : p)
        x = g.vec(s);
      break;
    }
    case 1: {  // two layers resting about a thickness apart, moving a little: the simulator's bulk
      const double gap = std::ldexp(1.0, g.integer(-12, -8));
      const double move = gap * g.uniform(0.0, 3.0);
      for (int k = 0; k < 3; ++k) {
        p[k] = V(g.uniform(0, 0.01), g.uniform(0, 0.01), g.uniform(-1e-6, 1e-6));
        p[6 + k] = V(g.uniform(0, 0.01), g.uniform(0, 0.01), gap + g.uniform(-1e-6, 1e-6));
      }
      for (int k : {0, 1, 2, 6, 7, 8})
        p[k + 3] = p[k] + g.vec(move);
      break;
    }
    case 2: {  // degenerate: repeated corners, collinear corners, needles, on a small grid
      const double s = std::ldexp(1.0, g.integer(-10, 10));
      for (auto& x : p)
        x = g.grid(2) * s;
      p[g.integer(0, 2)] = p[g.integer(0, 2)];
      p[9 + g.integer(0, 2)] = p[6 + g.integer(0, 2)];
      p[4] = p[3] + (p[5] - p[3]) * std::ldexp(1.0, -g.integer(1, 40));
      break;
    }
    case 3: {  // magnitudes where squares and cross products overflow or underflow
      const double s =
          std::ldexp(1.0, g.integer(0, 1) == 0 ? g.integer(400, 1020) : g.integer(-1070, -900));
      for (auto& x : p)
        x = g.vec(s);
      break;
    }
    default: {  // non-finite coordinates among ordinary ones
      for (auto& x : p)
        x = g.vec(1.0);
      const double bad[] = {std::numeric_limits<double>::quiet_NaN(),
                            std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity()};
      p[g.integer(0, 11)][g.integer(0, 2)] = bad[g.integer(0, 2)];
      break;
    }
  }
  return p;
}

ccd_detail::Triangle tri(const Pair& p, int first) {
  return {&p[first], &p[first + 1], &p[first + 2]};
}

std::uint64_t bits(double x) {
  return std::bit_cast<std::uint64_t>(x);
}

// The Eigen formulation of triangles_filter_culls that the lane-generic code replaced.
namespace eigen_form {

double plane_separation(const ccd_detail::Triangle& a, const ccd_detail::Triangle& b) {
  const V u = *a[1] - *a[0], v = *a[2] - *a[0];
  const V w = u.cross(v);
  const double w2 = w.squaredNorm();
  if (!(w2 > 1e-6 * u.squaredNorm() * v.squaredNorm())) return 0.0;
  double lo = INFINITY, hi = -INFINITY;
  for (const V* p : b) {
    const double s = w.dot(*p - *a[0]);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  const double side = lo > 0.0 ? lo : (hi < 0.0 ? -hi : 0.0);
  return side / std::sqrt(w2);
}

double box_gap(const ccd_detail::Triangle& a, const ccd_detail::Triangle& b) {
  V lo_a = *a[0], hi_a = *a[0], lo_b = *b[0], hi_b = *b[0];
  for (int k = 1; k < 3; ++k) {
    lo_a = lo_a.cwiseMin(*a[k]);
    hi_a = hi_a.cwiseMax(*a[k]);
    lo_b = lo_b.cwiseMin(*b[k]);
    hi_b = hi_b.cwiseMax(*b[k]);
  }
  return (lo_b - hi_a).cwiseMax(lo_a - hi_b).cwiseMax(0.0).norm();
}

double slack(const ccd_detail::Triangle& a, const ccd_detail::Triangle& b) {
  double m = 1.0;
  for (const V* p : {a[0], a[1], a[2], b[0], b[1], b[2]})
    m = std::max(m, p->cwiseAbs().maxCoeff());
  return 1e-12 * m;
}

double bound_less(const ccd_detail::Triangle& a, const ccd_detail::Triangle& b, double s) {
  const double bound = std::max({box_gap(a, b), plane_separation(a, b), plane_separation(b, a)});
  return std::max(0.0, bound - s);
}

bool filter(const Pair& p, double thickness, double& bound_t1) {
  double move2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    const V da = p[3 + i] - p[i];
    for (int j = 0; j < 3; ++j)
      move2 = std::max(move2, (da - (p[9 + j] - p[6 + j])).squaredNorm());
  }
  const double s0 = slack(tri(p, 0), tri(p, 6)), s1 = slack(tri(p, 3), tri(p, 9));
  const double eps = std::max(s0, s1);
  bound_t1 = bound_less(tri(p, 3), tri(p, 9), s1);
  const double bound = 0.5 * (bound_less(tri(p, 0), tri(p, 6), s0) + bound_t1 - std::sqrt(move2));
  return std::isfinite(bound) && bound > thickness + eps;
}

}  // namespace eigen_form

constexpr int kFamilies = 5;

TEST(FaceBatch, EveryInstructionSetGivesTheScalarVerdictAndBoundBitForBit) {
  Gen g(20261129);
  int compared = 0, culled = 0, kept = 0;
  for (int round = 0; round < 60; ++round) {
    FacePairBatch b;
    // Every batch size from 1 to the capacity occurs: partial vectors at the end.
    const int n = round < FacePairBatch::kCapacity ? round + 1 : FacePairBatch::kCapacity;
    std::vector<Pair> pairs;
    for (int i = 0; i < n; ++i) {
      pairs.push_back(make_pair(g, (round + i) % kFamilies));
      const Pair& p = pairs.back();
      b.push(tri(p, 0), tri(p, 3), tri(p, 6), tri(p, 9));
    }
    ASSERT_EQ(b.size, n);
    const double thickness = round % 3 == 0 ? 0.0 : std::ldexp(1.0, -g.integer(10, 20));
    std::array<bool, FacePairBatch::kCapacity> want{}, got{};
    std::array<double, FacePairBatch::kCapacity> want_d{}, got_d{};
    ASSERT_TRUE(
        ccd_detail::triangles_filter_batch_with(0, b, thickness, want.data(), want_d.data()));
    for (int i = 0; i < n; ++i) {
      double d1 = -1.0;
      const Pair& p = pairs[i];
      EXPECT_EQ(want[i], ccd_detail::triangles_filter_culls(tri(p, 0), tri(p, 3), tri(p, 6),
                                                            tri(p, 9), thickness, &d1));
      EXPECT_EQ(bits(want_d[i]), bits(d1));
      (want[i] ? culled : kept) += 1;
    }
    for (int isa = 1; isa <= 4; ++isa) {
      got.fill(false);
      got_d.fill(-1.0);
      const bool ran =
          isa == 4
              ? (ccd_detail::triangles_filter_batch(b, thickness, got.data(), got_d.data()), true)
              : ccd_detail::triangles_filter_batch_with(isa, b, thickness, got.data(),
                                                        got_d.data());
      test::note_isa("triangles_filter_batch", isa, ran);
      if (!ran) continue;
      for (int i = 0; i < n; ++i) {
        ASSERT_EQ(got[i], want[i]) << "isa " << isa << " round " << round << " pair " << i;
        ASSERT_EQ(bits(got_d[i]), bits(want_d[i]))
            << "isa " << isa << " round " << round << " pair " << i;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 1000);
  // Both verdicts occur, or the comparison says little.
  EXPECT_GT(culled, 100);
  EXPECT_GT(kept, 100);
}

TEST(FaceBatch, ScalarFilterIsTheEigenFormulationBitForBitOnFiniteInput) {
  Gen g(7);
  int culled = 0;
  for (int i = 0; i < 20000; ++i) {
    const Pair p = make_pair(g, i % 4);  // the finite families
    const double thickness = std::ldexp(1.0, -g.integer(10, 20));
    double want_d = 0.0, got_d = 0.0;
    const bool want = eigen_form::filter(p, thickness, want_d);
    const bool got = ccd_detail::triangles_filter_culls(tri(p, 0), tri(p, 3), tri(p, 6), tri(p, 9),
                                                        thickness, &got_d);
    ASSERT_EQ(got, want) << "pair " << i;
    ASSERT_EQ(bits(got_d), bits(want_d)) << "pair " << i;
    culled += got ? 1 : 0;
  }
  EXPECT_GT(culled, 1000);
}

TEST(FaceBatch, StaticBoundOfEveryInstructionSetIsTheScalarBoundBitForBit) {
  Gen g(99);
  int compared = 0, positive = 0;
  for (int round = 0; round < 60; ++round) {
    ccd_detail::StaticFacePairBatch b;
    const int n = round < ccd_detail::StaticFacePairBatch::kCapacity
                      ? round + 1
                      : ccd_detail::StaticFacePairBatch::kCapacity;
    std::vector<Pair> pairs;
    for (int i = 0; i < n; ++i) {
      pairs.push_back(make_pair(g, (round + i) % kFamilies));
      b.push(tri(pairs.back(), 3), tri(pairs.back(), 9));
    }
    std::array<double, ccd_detail::StaticFacePairBatch::kCapacity> want{}, got{};
    for (int i = 0; i < n; ++i) {
      want[i] = ccd_detail::triangle_triangle_bound(tri(pairs[i], 3), tri(pairs[i], 9));
      positive += want[i] > 0 ? 1 : 0;
    }
    for (int isa = 0; isa <= 4; ++isa) {
      got.fill(-1.0);
      const bool ran = isa == 4 ? (ccd_detail::triangle_bound_batch(b, got.data()), true)
                                : ccd_detail::triangle_bound_batch_with(isa, b, got.data());
      test::note_isa("triangle_bound_batch", isa, ran);
      if (!ran) continue;
      for (int i = 0; i < n; ++i) {
        ASSERT_EQ(bits(got[i]), bits(want[i])) << "isa " << isa << " round " << round;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 1000);
  EXPECT_GT(positive, 100);
}

// The bound at t1 never exceeds the distance of any VF or EE feature pair of the two triangles.
TEST(FaceBatch, BoundAtT1IsALowerBoundOfEveryFeatureDistance) {
  Gen g(11);
  int positive = 0;
  for (int i = 0; i < 5000; ++i) {
    const Pair p = make_pair(g, i % 3);
    FacePairBatch b;
    b.push(tri(p, 0), tri(p, 3), tri(p, 6), tri(p, 9));
    bool culls = false;
    double d1 = 0.0;
    ccd_detail::triangles_filter_batch(b, 0.0, &culls, &d1);
    const auto a = tri(p, 3), c = tri(p, 9);
    double nearest = INFINITY;
    for (int k = 0; k < 3; ++k) {
      nearest = std::min(nearest, point_triangle_proximity(*a[k], *c[0], *c[1], *c[2]).distance);
      nearest = std::min(nearest, point_triangle_proximity(*c[k], *a[0], *a[1], *a[2]).distance);
      for (int l = 0; l < 3; ++l) {
        nearest = std::min(
            nearest, edge_edge_proximity(*a[k], *a[(k + 1) % 3], *c[l], *c[(l + 1) % 3]).distance);
      }
    }
    ASSERT_LE(d1, nearest) << "pair " << i;
    positive += d1 > 0 ? 1 : 0;
  }
  EXPECT_GT(positive, 1000);
}

}  // namespace
}  // namespace clothcd::face_batch_test
