// The distance filter never culls a pair that comes within the thickness: every cull is checked
// by sampling the distance along the motion (exact distances at 2001 instants), on random resting
// and moving pairs at several scales.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>

#include "clothcd/ccd/proximity.hpp"
#include "clothcd/ccd/queries.hpp"

namespace clothcd {
namespace {

using V = Eigen::Vector3d;
constexpr int kSamples = 2000;

// Smallest of the exact distances at 2001 instants of the linear motion.
template <class Distance>
double sampled_min(Distance&& at) {
  double d = INFINITY;
  for (int i = 0; i <= kSamples; ++i)
    d = std::min(d, at(double(i) / kSamples));
  return d;
}

V lerp(const V& a, const V& b, double t) {
  return a + t * (b - a);
}

double min_distance(const VertexFaceQuery& q) {
  return sampled_min([&](double t) {
    return point_triangle_proximity(lerp(q.v_t0, q.v_t1, t), lerp(q.f0_t0, q.f0_t1, t),
                                    lerp(q.f1_t0, q.f1_t1, t), lerp(q.f2_t0, q.f2_t1, t))
        .distance;
  });
}

double min_distance(const EdgeEdgeQuery& q) {
  return sampled_min([&](double t) {
    return edge_edge_proximity(lerp(q.ea0_t0, q.ea0_t1, t), lerp(q.ea1_t0, q.ea1_t1, t),
                               lerp(q.eb0_t0, q.eb0_t1, t), lerp(q.eb1_t0, q.eb1_t1, t))
        .distance;
  });
}

// The whole-step bound with the exact distances, as docs/ccd.md states it (slack 1e-12 x the
// largest coordinate magnitude, at least 1e-12): the filter's lower-bound shortcut must give the
// same answer.
template <std::size_t N, std::size_t M>
bool whole_step_reference(const std::array<V, N>& a0, const std::array<V, N>& a1,
                          const std::array<V, M>& b0, const std::array<V, M>& b1, double d0,
                          double d1, double thickness) {
  double move2 = 0.0, m = 1.0;
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t j = 0; j < M; ++j)
      move2 = std::max(move2, ((a1[i] - a0[i]) - (b1[j] - b0[j])).squaredNorm());
  }
  for (const auto* l : {&a0, &a1})
    for (const V& p : *l)
      m = std::max(m, p.cwiseAbs().maxCoeff());
  for (const auto* l : {&b0, &b1})
    for (const V& p : *l)
      m = std::max(m, p.cwiseAbs().maxCoeff());
  return 0.5 * (d0 + d1 - std::sqrt(move2)) > thickness + 1e-12 * m;
}

bool reference_culls(const VertexFaceQuery& q, double thickness) {
  return whole_step_reference<1, 3>(
      {q.v_t0}, {q.v_t1}, {q.f0_t0, q.f1_t0, q.f2_t0}, {q.f0_t1, q.f1_t1, q.f2_t1},
      point_triangle_proximity(q.v_t0, q.f0_t0, q.f1_t0, q.f2_t0).distance,
      point_triangle_proximity(q.v_t1, q.f0_t1, q.f1_t1, q.f2_t1).distance, thickness);
}

bool reference_culls(const EdgeEdgeQuery& q, double thickness) {
  return whole_step_reference<2, 2>(
      {q.ea0_t0, q.ea1_t0}, {q.ea0_t1, q.ea1_t1}, {q.eb0_t0, q.eb1_t0}, {q.eb0_t1, q.eb1_t1},
      edge_edge_proximity(q.ea0_t0, q.ea1_t0, q.eb0_t0, q.eb1_t0).distance,
      edge_edge_proximity(q.ea0_t1, q.ea1_t1, q.eb0_t1, q.eb1_t1).distance, thickness);
}

// Features near each other (resting-contact-like gaps) with moves up to `move` per vertex.
struct Generator {
  std::mt19937_64 rng;
  double scale, move;
  V point() { return scale * V(u(rng), u(rng), u(rng)); }
  V step(const V& p) { return p + move * V(u(rng), u(rng), u(rng)); }
  std::uniform_real_distribution<> u{-1.0, 1.0};
};

// Random cases per scale and move ratio: the sampled minimum distance is slow under the
// sanitizers (135 s there against 2.4 s in Release with 300), so they run fewer.
#ifdef CLOTHCD_TEST_SANITIZED
constexpr int kCasesPerSetting = 60;
#else
constexpr int kCasesPerSetting = 300;
#endif

TEST(DistanceFilter, NeverCullsAPairThatComesWithinTheThickness) {
  // Depth 0 is the whole-step bound; deeper filters bisect the step where it fails.
  for (int depth : {0, 3, 6}) {
    int culled_vf = 0, culled_ee = 0, cases = 0;
    for (double scale : {1e-3, 1e-2, 1.0}) {
      for (double move_ratio : {0.01, 0.1, 1.0}) {
        Generator g{std::mt19937_64(17), scale, move_ratio * scale};
        for (int i = 0; i < kCasesPerSetting; ++i, ++cases) {
          const double thickness = scale * std::pow(10.0, -1 - 3 * (i % 4) / 3.0);
          // A cull is checked by sampling; a pair kept must be kept by the whole-step bound too
          // (bisection only adds culls).
          auto check = [&](const auto& q, int& culled) {
            if (depth == 0) {
              ASSERT_EQ(distance_filter_culls(q, thickness), reference_culls(q, thickness))
                  << "scale " << scale << " case " << i;
            }
            if (distance_filter_culls(q, thickness, depth)) {
              ++culled;
              ASSERT_GT(min_distance(q), thickness)
                  << "depth " << depth << " scale " << scale << " case " << i;
            } else {
              ASSERT_FALSE(distance_filter_culls(q, thickness));
            }
          };
          const V a = g.point(), b = g.point(), c = g.point(), d = g.point();
          check(VertexFaceQuery{a, b, c, d, g.step(a), g.step(b), g.step(c), g.step(d)}, culled_vf);
          check(EdgeEdgeQuery{a, b, c, d, g.step(a), g.step(b), g.step(c), g.step(d)}, culled_ee);
        }
      }
    }
    // The filter must also do its job: small relative moves are culled often.
    EXPECT_GT(culled_vf, cases / 4) << "depth " << depth;
    EXPECT_GT(culled_ee, cases / 4) << "depth " << depth;
  }
}

TEST(DistanceFilter, BisectionCullsANearMissTheWholeStepBoundCannot) {
  // A vertex slides 5 cm across a face 1 mm above it: the whole-step bound (1 + 1 - 50) / 2 mm
  // proves nothing, 1/64 of the step moves it 0.8 mm < 2 (1 - 0.01) mm.
  const V a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const VertexFaceQuery vf{V(0.2, 0.2, 0.001), a, b, c, V(0.25, 0.2, 0.001), a, b, c};
  EXPECT_FALSE(distance_filter_culls(vf, 1e-5));
  EXPECT_FALSE(distance_filter_culls(vf, 1e-5, 4));
  EXPECT_TRUE(distance_filter_culls(vf, 1e-5, 6));
  EXPECT_FALSE(distance_filter_culls(vf, 0.0011, 10));  // thicker than the gap
  // An edge sliding along another 1 mm above it.
  const EdgeEdgeQuery ee{V(0.5, -1, 0.001),  V(0.5, 1, 0.001),  a, b,
                         V(0.55, -1, 0.001), V(0.55, 1, 0.001), a, b};
  EXPECT_FALSE(distance_filter_culls(ee, 1e-5));
  EXPECT_TRUE(distance_filter_culls(ee, 1e-5, 6));
}

TEST(DistanceFilter, RestingPairMovingTogetherIsCulled) {
  // A vertex 1 mm above a face; both translate by 5 cm: the gap never changes.
  const V shift(0.05, -0.02, 0.03);
  const V p(0.2, 0.2, 0.001), a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const VertexFaceQuery q{p, a, b, c, p + shift, a + shift, b + shift, c + shift};
  EXPECT_TRUE(distance_filter_culls(q, 1e-5));
  EXPECT_FALSE(distance_filter_culls(q, 0.0011));  // thicker than the gap
}

TEST(DistanceFilter, CrossingPairIsNotCulled) {
  const V a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const VertexFaceQuery vf{V(0.2, 0.2, 0.1), a, b, c, V(0.2, 0.2, -0.1), a, b, c};
  EXPECT_FALSE(distance_filter_culls(vf, 0.0));
  const EdgeEdgeQuery ee{V(0.5, -1, 0.1),  V(0.5, 1, 0.1),  V(0, 0, 0), V(1, 0, 0),
                         V(0.5, -1, -0.1), V(0.5, 1, -0.1), V(0, 0, 0), V(1, 0, 0)};
  EXPECT_FALSE(distance_filter_culls(ee, 0.0));
}

// The triangle pair's filter culls only where the distance filter culls each of its 15 feature
// pairs (checked at depth 0 and 6, and by sampling the pair's distance), on random, layered
// (two cloth layers resting on each other, moving together or sliding) and crossing pairs.
TEST(DistanceFilter, TrianglePairCullsOnlyWhereEveryFeaturePairCulls) {
  int culled = 0, layered_culled = 0, cases = 0;
  for (double scale : {1e-2, 1.0}) {
    for (double move_ratio : {0.01, 0.1, 1.0}) {
      Generator g{std::mt19937_64(29), scale, move_ratio * scale};
      for (int i = 0; i < kCasesPerSetting / 3; ++i, ++cases) {
        const double thickness = scale * std::pow(10.0, -2 - (i % 3));
        std::array<V, 3> a0{g.point(), g.point(), g.point()}, b0{g.point(), g.point(), g.point()};
        const bool layer = i % 2 == 1;
        if (layer) {  // b rests on a, 0.5-10% of the scale above it
          const V n = (a0[1] - a0[0]).cross(a0[2] - a0[0]).normalized();
          const double gap = scale * (0.005 + 0.095 * 0.5 * (1 + g.u(g.rng)));
          for (int k = 0; k < 3; ++k)
            b0[k] = a0[(k + 2) % 3] + gap * n + 0.01 * scale * V(g.u(g.rng), 0, 0);
        }
        std::array<V, 3> a1, b1;
        const V common = g.step(V::Zero());
        for (int k = 0; k < 3; ++k) {  // a shared motion plus each vertex's own, smaller one
          a1[k] = a0[k] + common + 0.1 * (g.step(a0[k]) - a0[k]);
          b1[k] = b0[k] + common + 0.1 * (g.step(b0[k]) - b0[k]);
        }
        const TriangleTriangleQuery q{a0[0], a0[1], a0[2], b0[0], b0[1], b0[2],
                                      a1[0], a1[1], a1[2], b1[0], b1[1], b1[2]};
        if (!distance_filter_culls(q, thickness)) continue;
        ++culled;
        layered_culled += layer;
        for (int k = 0; k < 3; ++k) {
          const VertexFaceQuery vf_ab{a0[k], b0[0], b0[1], b0[2], a1[k], b1[0], b1[1], b1[2]};
          const VertexFaceQuery vf_ba{b0[k], a0[0], a0[1], a0[2], b1[k], a1[0], a1[1], a1[2]};
          for (const auto* vf : {&vf_ab, &vf_ba}) {
            ASSERT_TRUE(distance_filter_culls(*vf, thickness)) << scale << " " << i;
            ASSERT_TRUE(distance_filter_culls(*vf, thickness, 6)) << scale << " " << i;
            ASSERT_GT(min_distance(*vf), thickness) << scale << " " << i;
          }
          for (int j = 0; j < 3; ++j) {
            const int k2 = (k + 1) % 3, j2 = (j + 1) % 3;
            const EdgeEdgeQuery ee{a0[k], a0[k2], b0[j], b0[j2], a1[k], a1[k2], b1[j], b1[j2]};
            ASSERT_TRUE(distance_filter_culls(ee, thickness)) << scale << " " << i;
            ASSERT_TRUE(distance_filter_culls(ee, thickness, 6)) << scale << " " << i;
            ASSERT_GT(min_distance(ee), thickness) << scale << " " << i;
          }
        }
      }
    }
  }
  // It does its job on layers (the narrow phase's bulk), and not only there.
  EXPECT_GT(layered_culled, cases / 4);
  EXPECT_GT(culled, layered_culled);
  // A vertex of b passing through a: never culled.
  const V o(0, 0, 0), x(1, 0, 0), y(0, 1, 0);
  const V p(0.2, 0.2, 0.1), dp(0, 0, -0.2), s(0.9, 0.9, 0.1), t(0.2, 0.9, 0.1);
  EXPECT_FALSE(
      distance_filter_culls(TriangleTriangleQuery{o, x, y, p, s, t, o, x, y, p + dp, s, t}, 0.0));
  // Resting layers 1 mm apart moving together: culled below the gap, not above it.
  const V up(0, 0, 0.001), shift(0.05, -0.02, 0.03);
  const TriangleTriangleQuery rest{
      o,         x,         y,         o + up,         x + up,         y + up,
      o + shift, x + shift, y + shift, o + up + shift, x + up + shift, y + up + shift};
  EXPECT_TRUE(distance_filter_culls(rest, 1e-5));
  EXPECT_FALSE(distance_filter_culls(rest, 0.0011));
}

TEST(DistanceFilter, NonFiniteThrowsLikeTheKernels) {
  const V a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), n(NAN, 0, 0);
  EXPECT_THROW((void)distance_filter_culls(VertexFaceQuery{n, a, b, c, n, a, b, c}, 0.0),
               std::invalid_argument);
  EXPECT_THROW((void)distance_filter_culls(EdgeEdgeQuery{n, a, b, c, n, a, b, c}, 0.0),
               std::invalid_argument);
  EXPECT_THROW(
      (void)distance_filter_culls(TriangleTriangleQuery{a, b, c, a, b, n, a, b, c, a, b, c}, 0.0),
      std::invalid_argument);
}

}  // namespace
}  // namespace clothcd
