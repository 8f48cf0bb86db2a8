// Seeded random CCD queries against the exact oracle: zero false negatives, conservative time of
// impact. Families: generic positions with planted near-contacts over many scales, and points on
// a small integer grid (exact coplanarity, parallel and collinear edges, touching at t = 0 or 1).
// A failure prints its seed and index.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "clothcd/ccd/proximity.hpp"
#include "clothcd/ccd/queries.hpp"
#include "exact_oracle.hpp"
#include "support/random_gen.hpp"

// Queries per seed and family: small for the unit label, larger in the `slow` build.
#ifndef CLOTHCD_CCD_RANDOM_COUNT
#define CLOTHCD_CCD_RANDOM_COUNT 25
#endif

namespace clothcd {
namespace {

constexpr int kCount = CLOTHCD_CCD_RANDOM_COUNT;

using V = Eigen::Vector3d;

using test::Gen;

// 8 points: v/ea0, f0/ea1, f1/eb0, f2/eb1 at t0, then at t1.
using Points = std::array<V, 8>;

// Generic points with a planted contact at time ts (rounded, so the oracle decides), plus noise.
Points planted(Gen& g, bool vf) {
  const double s = g.scale();
  const V shift = g.vec(4 * s);
  Points p;
  for (int i = 0; i < 8; ++i)
    p[i] = shift + g.vec(s);
  const double ts = g.uniform(0, 1), u = g.uniform(-0.1, 1.1), w = g.uniform(-0.1, 1.1);
  auto at = [&](int k) { return (1 - ts) * p[k] + ts * p[k + 4]; };
  if (!vf) {
    // eb0 + w (eb1 - eb0) should meet ea0 + u (ea1 - ea0): move eb's t1 positions accordingly.
    const V on_a = at(0) + u * (at(1) - at(0));
    const V on_b = at(2) + w * (at(3) - at(2));
    const V delta = (on_a - on_b) / std::max(ts, 1e-3);
    p[6] += delta;
    p[7] += delta;
  } else {
    // Vertex: p0 at t0 fixed, choose the t1 position so that it reaches the face point at ts.
    const V target = at(1) + 0.5 * u * (at(2) - at(1)) + 0.5 * w * (at(3) - at(1));
    p[4] = p[0] + (target - p[0]) / std::max(ts, 1e-3);
  }
  // Round to a grid of s 2^-bits: generic positions whose exact rationals stay small enough for
  // the oracle; the contact survives only where the rounding keeps it (the oracle decides).
  const double cell = std::ldexp(s, -g.integer(12, 30));
  for (auto& x : p)
    x = (x / cell).array().round().matrix() * cell;
  return p;
}

Points on_grid(Gen& g) {
  Points p;
  const double s = std::ldexp(1.0, g.integer(-20, 20));
  const int k = g.integer(1, 2);
  for (int i = 0; i < 4; ++i) {
    p[i] = g.grid(k) * s;
    // Often no motion, or motion within a plane, to produce sliding and resting cases.
    const int mode = g.integer(0, 3);
    if (mode == 0) {
      p[i + 4] = p[i];
    } else if (mode == 1) {
      V d = g.grid(k);
      d.z() = 0;
      p[i + 4] = p[i] + d * s;
    } else {
      p[i + 4] = g.grid(k) * s;
    }
  }
  if (g.integer(0, 2) == 0) {
    for (auto& x : p)
      x.z() = 0;  // everything coplanar
  }
  return p;
}

VertexFaceQuery as_vf(const Points& p) {
  return {p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]};
}
EdgeEdgeQuery as_ee(const Points& p) {
  return {p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]};
}

struct Tally {
  int queries = 0, positives = 0, fp = 0;
};

void check_one(const Points& p, bool vf, std::uint64_t seed, int i, Tally& tally) {
  const bool truth =
      vf ? test::exact_vertex_face_contact(as_vf(p)) : test::exact_edge_edge_contact(as_ee(p));
  ++tally.queries;
  tally.positives += truth;
  for (bool fast : {true, false}) {
    CcdOptions opt;
    opt.fast_path = fast;
    const CcdResult r = vf ? vertex_face_ccd(as_vf(p), opt) : edge_edge_ccd(as_ee(p), opt);
    ASSERT_TRUE(r.toi >= 0 && r.toi <= 1) << "seed " << seed << " #" << i;
    if (truth) {
      ASSERT_TRUE(r.hit) << "false negative: seed " << seed << " #" << i << (vf ? " VF" : " EE")
                         << (fast ? " fast" : " inclusion");
      if (r.toi > 0) {
        const double before = std::nextafter(r.toi, 0.0);
        ASSERT_FALSE(vf ? test::exact_vertex_face_contact(as_vf(p), before)
                        : test::exact_edge_edge_contact(as_ee(p), before))
            << "toi " << r.toi << " after the first contact: seed " << seed << " #" << i;
      }
    } else if (fast) {
      tally.fp += r.hit;
    }
  }
}

TEST(CcdRandom, PlantedContactsOverScales) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    Gen g(seed);
    Tally vf, ee;
    for (int i = 0; i < kCount; ++i) {
      check_one(planted(g, true), true, seed, i, vf);
      check_one(planted(g, false), false, seed, i, ee);
      if (HasFatalFailure()) return;
    }
    std::printf("seed %llu: VF %d queries, %d positive, %d FP; EE %d, %d, %d FP\n",
                static_cast<unsigned long long>(seed), vf.queries, vf.positives, vf.fp, ee.queries,
                ee.positives, ee.fp);
    EXPECT_GT(vf.positives, 0);
    EXPECT_GT(ee.positives, 0);
  }
}

TEST(CcdRandom, IntegerGridDegeneracies) {
  for (std::uint64_t seed = 100; seed < 104; ++seed) {
    Gen g(seed);
    Tally vf, ee;
    for (int i = 0; i < kCount; ++i) {
      check_one(on_grid(g), true, seed, i, vf);
      check_one(on_grid(g), false, seed, i, ee);
      if (HasFatalFailure()) return;
    }
    std::printf("seed %llu: VF %d queries, %d positive, %d FP; EE %d, %d, %d FP\n",
                static_cast<unsigned long long>(seed), vf.queries, vf.positives, vf.fp, ee.queries,
                ee.positives, ee.fp);
    EXPECT_GT(vf.positives, 0);
    EXPECT_GT(ee.positives, 0);
  }
}

// With thickness h: wherever a sampled time brings the features within h (measured with the
// discrete proximity functions, with a relative margin for their rounding), the kernel reports a
// hit no later than that time.
TEST(CcdRandom, ThicknessNeverMissesSampledProximity) {
  for (std::uint64_t seed = 200; seed < 204; ++seed) {
    Gen g(seed);
    int witnessed = 0;
    for (int i = 0; i < 4 * kCount; ++i) {
      const bool vf = i % 2 == 0;
      const Points p = planted(g, vf);
      const double extent = (p[0] - p[1]).norm() + (p[2] - p[3]).norm();
      const double h = extent * std::ldexp(1.0, g.integer(-20, -2));
      CcdOptions opt;
      opt.thickness = h;
      const CcdResult r = vf ? vertex_face_ccd(as_vf(p), opt) : edge_edge_ccd(as_ee(p), opt);
      for (int k = 0; k <= 32; ++k) {
        const double t = k / 32.0;
        V x[4];
        for (int j = 0; j < 4; ++j)
          x[j] = (1 - t) * p[j] + t * p[j + 4];
        const double d = vf ? point_triangle_proximity(x[0], x[1], x[2], x[3]).distance
                            : edge_edge_proximity(x[0], x[1], x[2], x[3]).distance;
        if (d < h * (1 - 1e-9)) {
          ++witnessed;
          ASSERT_TRUE(r.hit) << "seed " << seed << " #" << i << " t " << t;
          ASSERT_LE(r.toi, t) << "seed " << seed << " #" << i;
          break;
        }
      }
    }
    EXPECT_GT(witnessed, 0);
  }
}

}  // namespace
}  // namespace clothcd
