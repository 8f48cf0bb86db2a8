// Discrete proximity against brute force (dense sampling of the triangle / both segments) and on
// named degenerate cases with known answers.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "clothcd/ccd/proximity.hpp"

namespace clothcd {
namespace {

using V = Eigen::Vector3d;

double brute_point_triangle(const V& p, const V& a, const V& b, const V& c, int n) {
  double best = INFINITY;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const double u = double(i) / n, v = double(j) / n;
      best = std::min(best, (p - (a + u * (b - a) + v * (c - a))).norm());
    }
  }
  return best;
}

double brute_edge_edge(const V& a0, const V& a1, const V& b0, const V& b1, int n) {
  double best = INFINITY;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const double s = double(i) / n, t = double(j) / n;
      best = std::min(best, ((a0 + s * (a1 - a0)) - (b0 + t * (b1 - b0))).norm());
    }
  }
  return best;
}

// The candidates compared by their distances, every one with its square root: what the
// squared-distance prefilter of edge_edge_proximity / point_triangle_proximity must reproduce
// bit for bit (ties included: the first of equal candidates stays).
EdgeEdgeProximity reference_edge_edge(const V& ea0, const V& ea1, const V& eb0, const V& eb1) {
  EdgeEdgeProximity best;
  best.distance = INFINITY;
  auto consider = [&](double s, double t) {
    const V ca = ea0 + s * (ea1 - ea0), cb = eb0 + t * (eb1 - eb0);
    const double d = (ca - cb).norm();
    if (d < best.distance) best = EdgeEdgeProximity{d, s, t, ca, cb};
  };
  consider(0, point_segment_parameter(ea0, eb0, eb1));
  consider(1, point_segment_parameter(ea1, eb0, eb1));
  consider(point_segment_parameter(eb0, ea0, ea1), 0);
  consider(point_segment_parameter(eb1, ea0, ea1), 1);
  const V da = ea1 - ea0, db = eb1 - eb0, r = ea0 - eb0;
  const double a = da.dot(da), b = da.dot(db), c = db.dot(db), d = da.dot(r), e = db.dot(r);
  const double den = a * c - b * b;
  if (den > 1e-14 * a * c) {
    consider(std::clamp((b * e - c * d) / den, 0.0, 1.0),
             std::clamp((a * e - b * d) / den, 0.0, 1.0));
  }
  return best;
}

PointTriangleProximity reference_point_triangle(const V& p, const V& f0, const V& f1, const V& f2) {
  PointTriangleProximity best;
  best.distance = INFINITY;
  const V* v[3] = {&f0, &f1, &f2};
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const double s = point_segment_parameter(p, *v[i], *v[j]);
    const V c = *v[i] + s * (*v[j] - *v[i]);
    const double d = (p - c).norm();
    if (d < best.distance) {
      best.distance = d;
      best.closest = c;
      best.weights.setZero();
      best.weights[i] = 1 - s;
      best.weights[j] = s;
    }
  }
  const V e1 = f1 - f0, e2 = f2 - f0, w = p - f0;
  const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
  const double r1 = w.dot(e1), r2 = w.dot(e2);
  const double det = g11 * g22 - g12 * g12;
  if (det > 1e-12 * g11 * g22) {
    const double a = (r1 * g22 - r2 * g12) / det;
    const double b = (r2 * g11 - r1 * g12) / det;
    if (a >= 0 && b >= 0 && a + b <= 1) {
      const V c = f0 + a * e1 + b * e2;
      const double d = (p - c).norm();
      if (d < best.distance) {
        best.distance = d;
        best.closest = c;
        best.weights = V(1 - a - b, a, b);
      }
    }
  }
  return best;
}

TEST(CcdProximity, SquaredDistancePrefilterChoosesTheSameCandidateBitForBit) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<> u(-1, 1);
  // Coordinates on a coarse lattice make equal candidate distances (ties) common: parallel and
  // collinear segments, points above vertices and edges.
  std::uniform_int_distribution<> lattice(-2, 2);
  for (int i = 0; i < 20000; ++i) {
    const bool coarse = i % 2 == 1;
    auto vec = [&] {
      return coarse ? V(lattice(rng), lattice(rng), lattice(rng)) : V(u(rng), u(rng), u(rng));
    };
    const V a = vec(), b = vec(), c = vec(), d = vec();
    const EdgeEdgeProximity got = edge_edge_proximity(a, b, c, d);
    const EdgeEdgeProximity want = reference_edge_edge(a, b, c, d);
    ASSERT_EQ(got.distance, want.distance) << i;
    ASSERT_EQ(got.s, want.s) << i;
    ASSERT_EQ(got.t, want.t) << i;
    ASSERT_EQ(got.closest_a, want.closest_a) << i;
    ASSERT_EQ(got.closest_b, want.closest_b) << i;
    const PointTriangleProximity pt = point_triangle_proximity(a, b, c, d);
    const PointTriangleProximity pw = reference_point_triangle(a, b, c, d);
    ASSERT_EQ(pt.distance, pw.distance) << i;
    ASSERT_EQ(pt.weights, pw.weights) << i;
    ASSERT_EQ(pt.closest, pw.closest) << i;
  }
}

TEST(CcdProximity, RandomAgainstBruteForce) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<> u(-1, 1);
    auto vec = [&] { return V(u(rng), u(rng), u(rng)); };
    for (int i = 0; i < 100; ++i) {
      const V p = vec(), a = vec(), b = vec(), c = vec(), d = vec();
      const int n = 150;
      const auto pt = point_triangle_proximity(p, a, b, c);
      const double bpt = brute_point_triangle(p, a, b, c, n);
      // Never above a sampled distance; below it by at most the sampling resolution.
      const double res = 2.0 * ((b - a).norm() + (c - a).norm()) / n;
      EXPECT_LE(pt.distance, bpt + 1e-12) << seed << " " << i;
      EXPECT_GE(pt.distance, bpt - res) << seed << " " << i;
      EXPECT_NEAR(pt.weights.sum(), 1.0, 1e-12);
      EXPECT_GE(pt.weights.minCoeff(), 0.0);
      const V from_weights = pt.weights[0] * a + pt.weights[1] * b + pt.weights[2] * c;
      EXPECT_NEAR((from_weights - pt.closest).norm(), 0.0, 1e-12);
      EXPECT_NEAR((p - pt.closest).norm(), pt.distance, 1e-12);

      const auto ee = edge_edge_proximity(p, a, c, d);
      const double bee = brute_edge_edge(p, a, c, d, n);
      const double res2 = ((a - p).norm() + (d - c).norm()) / n;
      EXPECT_LE(ee.distance, bee + 1e-12) << seed << " " << i;
      EXPECT_GE(ee.distance, bee - res2) << seed << " " << i;
      EXPECT_GE(ee.s, 0.0);
      EXPECT_LE(ee.s, 1.0);
      EXPECT_GE(ee.t, 0.0);
      EXPECT_LE(ee.t, 1.0);
      EXPECT_NEAR((ee.closest_a - ee.closest_b).norm(), ee.distance, 1e-12);
    }
  }
}

TEST(CcdProximity, DegenerateCases) {
  const V o(0, 0, 0), x(1, 0, 0), x2(2, 0, 0), y(0, 1, 0);
  // Triangle collapsed to a segment: distance to that segment.
  EXPECT_NEAR(point_triangle_proximity(V(0.5, 1, 0), o, x, x2).distance, 1.0, 1e-15);
  EXPECT_NEAR(point_triangle_proximity(V(3, 0, 0), o, x, x2).distance, 1.0, 1e-15);
  // Triangle collapsed to a point.
  EXPECT_NEAR(point_triangle_proximity(V(0, 3, 4), o, o, o).distance, 5.0, 1e-15);
  // Point in the interior, above it, and beyond a corner.
  EXPECT_NEAR(point_triangle_proximity(V(0.25, 0.25, 2), o, x, y).distance, 2.0, 1e-15);
  const auto corner = point_triangle_proximity(V(-1, -1, 0), o, x, y);
  EXPECT_NEAR(corner.distance, std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(corner.weights[0], 1.0, 1e-15);
  // Parallel edges, overlapping: distance is the offset.
  EXPECT_NEAR(edge_edge_proximity(o, x, V(0.5, 1, 0), V(1.5, 1, 0)).distance, 1.0, 1e-15);
  // Parallel, not overlapping: end to end.
  EXPECT_NEAR(edge_edge_proximity(o, x, V(3, 0, 0), V(4, 0, 0)).distance, 2.0, 1e-15);
  // Collinear overlapping: touching.
  EXPECT_NEAR(edge_edge_proximity(o, x2, x, V(3, 0, 0)).distance, 0.0, 1e-15);
  // Zero-length edges.
  EXPECT_NEAR(edge_edge_proximity(y, y, o, x2).distance, 1.0, 1e-15);
  EXPECT_NEAR(edge_edge_proximity(y, y, o, o).distance, 1.0, 1e-15);
  // Crossing skew edges: interior solution.
  const auto skew = edge_edge_proximity(V(-1, 0, 0), V(1, 0, 0), V(0, -1, 1), V(0, 1, 1));
  EXPECT_NEAR(skew.distance, 1.0, 1e-15);
  EXPECT_NEAR(skew.s, 0.5, 1e-15);
  EXPECT_NEAR(skew.t, 0.5, 1e-15);
  EXPECT_THROW((void)edge_edge_proximity(V(NAN, 0, 0), o, o, x), std::invalid_argument);
  EXPECT_THROW((void)point_triangle_proximity(o, o, V(0, INFINITY, 0), x), std::invalid_argument);
}

// The lower bounds never exceed the exact distance, and the *_if_within forms give it exactly
// up to their limit, on random features at the unit scale and at a
// cloth's (millimetre features 1 m from the origin), and on near-degenerate ones: slivers,
// near-parallel edges, points close to a triangle's plane.
TEST(CcdProximity, LowerBoundsNeverExceedTheDistance) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<> u(-1, 1);
  long long positive = 0;
  for (const double size : {1.0, 1e-2, 1e-3}) {
    auto vec = [&](const V& at) { return V(at + size * V(u(rng), u(rng), u(rng))); };
    for (int i = 0; i < 20000; ++i) {
      const V at = i % 2 == 0 ? V::Zero() : V(0.7, 1.1, -0.4);
      V p = vec(at), a = vec(at), b = vec(at), c = vec(at), d = vec(at);
      switch (i % 5) {
        case 1:  // sliver: c nearly on ab
          c = a + 0.3 * (b - a) + 1e-9 * size * V(u(rng), u(rng), u(rng));
          break;
        case 2:  // near-parallel edges
          d = c + (a - p) * (1 + 1e-7 * u(rng)) + 1e-9 * size * V(u(rng), u(rng), u(rng));
          break;
        case 3:  // p within rounding of the triangle's plane
          p = a + u(rng) * (b - a) + u(rng) * (c - a);
          break;
        default:
          break;
      }
      const double pt = point_triangle_proximity(p, a, b, c).distance;
      const double lpt = point_triangle_distance_lower_bound(p, a, b, c);
      EXPECT_LE(lpt, pt) << size << " " << i;
      EXPECT_GE(lpt, 0.0);
      const double ee = edge_edge_proximity(p, a, c, d).distance;
      const double lee = edge_edge_distance_lower_bound(p, a, c, d);
      EXPECT_LE(lee, ee) << size << " " << i;
      EXPECT_GE(lee, 0.0);
      positive += (lpt > 0) + (lee > 0);
      // The *_if_within forms: the exact distance (bit for bit) up to the limit, above it after.
      for (const double limit : {0.0, 0.5 * pt, pt, 2 * pt, lpt}) {
        const double got = point_triangle_distance_if_within(p, a, b, c, limit);
        if (pt <= limit) {
          EXPECT_EQ(got, pt) << size << " " << i;
        } else {
          EXPECT_GT(got, limit) << size << " " << i;
        }
      }
      for (const double limit : {0.0, 0.5 * ee, ee, 2 * ee, lee}) {
        const double got = edge_edge_distance_if_within(p, a, c, d, limit);
        if (ee <= limit) {
          EXPECT_EQ(got, ee) << size << " " << i;
        } else {
          EXPECT_GT(got, limit) << size << " " << i;
        }
      }
    }
  }
  EXPECT_GT(positive, 30000);  // the bounds cull: most random pairs get a positive one
}

// Smallest of the 15 feature distances (6 VF, 9 EE) between triangles a and b.
double feature_distance(const std::array<V, 3>& a, const std::array<V, 3>& b) {
  double d = INFINITY;
  for (int i = 0; i < 3; ++i) {
    d = std::min(d, point_triangle_proximity(a[i], b[0], b[1], b[2]).distance);
    d = std::min(d, point_triangle_proximity(b[i], a[0], a[1], a[2]).distance);
    for (int j = 0; j < 3; ++j) {
      d = std::min(d, edge_edge_proximity(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]).distance);
    }
  }
  return d;
}

// The triangles' bound never exceeds any of their feature distances: random triangles, layers
// (b a jittered copy of a, offset along its normal, as two cloth layers resting on each other),
// slivers and crossing pairs, at the unit scale and at a cloth's.
TEST(CcdProximity, TriangleBoundNeverExceedsAnyFeatureDistance) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<> u(-1, 1);
  int positive = 0, layered = 0;
  for (const double size : {1.0, 1e-2}) {
    auto vec = [&](const V& at) { return V(at + size * V(u(rng), u(rng), u(rng))); };
    for (int i = 0; i < 8000; ++i) {
      const V at = i % 2 == 0 ? V::Zero() : V(0.7, 1.1, -0.4);
      std::array<V, 3> a{vec(at), vec(at), vec(at)}, b{vec(at), vec(at), vec(at)};
      switch (i % 4) {
        case 1: {  // a layer: b above a by up to 10% of the size, tilted a little
          const V n = (a[1] - a[0]).cross(a[2] - a[0]).normalized();
          const double gap = 0.1 * size * (0.5 + 0.5 * u(rng));
          for (int k = 0; k < 3; ++k)
            b[k] = a[(k + 1) % 3] + gap * n + 0.02 * size * V(u(rng), u(rng), u(rng));
          break;
        }
        case 2:  // a sliver
          a[2] = a[0] + 0.4 * (a[1] - a[0]) + 1e-9 * size * V(u(rng), u(rng), u(rng));
          break;
        case 3:  // b's vertex on a's plane, inside a
          b[0] = a[0] + 0.3 * (a[1] - a[0]) + 0.3 * (a[2] - a[0]);
          break;
        default:
          break;
      }
      const double bound =
          triangle_triangle_distance_lower_bound(a[0], a[1], a[2], b[0], b[1], b[2]);
      const double d = feature_distance(a, b);
      EXPECT_GE(bound, 0.0);
      EXPECT_LE(bound, d) << size << " " << i;
      positive += bound > 0;
      if (i % 4 == 1) layered += bound > 0.5 * d;
      if (i % 4 == 3) {
        EXPECT_EQ(bound, 0.0) << size << " " << i;
      }
    }
  }
  EXPECT_GT(positive, 4000);  // not vacuous
  EXPECT_GT(layered, 3000);   // and tight on layers, where the narrow phase needs it
}

TEST(CcdProximity, TriangleBoundIsThePlaneGapOfTwoLayers) {
  const V o(0, 0, 0), x(1, 0, 0), y(0, 1, 0), up(0, 0, 0.001);
  // Parallel layers 1 mm apart, b shifted sideways: the gap of the planes.
  EXPECT_NEAR(triangle_triangle_distance_lower_bound(o, x, y, o + up + V(0.3, 0.2, 0),
                                                     x + up + V(0.3, 0.2, 0), y + up),
              0.001, 1e-11);
  // b straddles a's plane and a straddles b's: nothing proved.
  EXPECT_EQ(triangle_triangle_distance_lower_bound(o, x, y, V(0.2, 0.2, -1), V(0.2, 0.2, 1),
                                                   V(0.3, 5, 0)),
            0.0);
  EXPECT_THROW((void)triangle_triangle_distance_lower_bound(o, x, y, V(NAN, 0, 0), x, y),
               std::invalid_argument);
}

TEST(CcdProximity, LowerBoundsAreTightWhereTheyShouldBe) {
  const V o(0, 0, 0), x(1, 0, 0), y(0, 1, 0);
  // Above the interior: the plane distance is the distance.
  EXPECT_NEAR(point_triangle_distance_lower_bound(V(0.25, 0.25, 2), o, x, y), 2.0, 1e-11);
  // Beside the triangle in its plane: the box gap.
  EXPECT_NEAR(point_triangle_distance_lower_bound(V(-3, 0.5, 0), o, x, y), 3.0, 1e-11);
  // Skew edges: the distance between their lines.
  EXPECT_NEAR(edge_edge_distance_lower_bound(V(-1, 0, 0), V(1, 0, 0), V(0, -1, 1), V(0, 1, 1)), 1.0,
              1e-11);
  // Parallel edges: no line bound, the box gap only.
  EXPECT_NEAR(edge_edge_distance_lower_bound(o, x, V(0.5, 1, 0), V(1.5, 1, 0)), 1.0, 1e-11);
  // Touching features: 0.
  EXPECT_EQ(point_triangle_distance_lower_bound(V(0.25, 0.25, 0), o, x, y), 0.0);
  EXPECT_EQ(edge_edge_distance_lower_bound(o, x, V(0.5, -1, 0), V(0.5, 1, 0)), 0.0);
  EXPECT_THROW((void)point_triangle_distance_lower_bound(V(NAN, 0, 0), o, x, y),
               std::invalid_argument);
  EXPECT_THROW((void)point_triangle_distance_if_within(V(NAN, 0, 0), o, x, y, 1.0),
               std::invalid_argument);
  EXPECT_THROW((void)edge_edge_distance_if_within(o, x, V(0, INFINITY, 0), y, 1.0),
               std::invalid_argument);
  EXPECT_THROW((void)edge_edge_distance_lower_bound(o, x, V(0, INFINITY, 0), y),
               std::invalid_argument);
}

}  // namespace
}  // namespace clothcd
