// The fast path's certified hits (CcdPath::Certified: a certain root of the coplanarity cubic
// with the contact point certainly inside over the root's time range) against the exact oracle:
// every certified hit is a real contact, its toi is never after the first contact, and the path
// is actually taken on transversal contacts. Contacts are planted at any time (also near 0 and 1),
// inside with a margin, near an edge (2^-40 .. 2^-5 of the feature size, either side), over
// scales 2^-30 .. 2^30 and with offsets up to 2^8 times the feature size (cancellation in the
// differences). A failure prints its seed and index.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <random>

#include "clothcd/ccd/queries.hpp"
#include "exact_oracle.hpp"

#ifndef CLOTHCD_CCD_CERTIFIED_COUNT
#define CLOTHCD_CCD_CERTIFIED_COUNT 20
#endif

namespace clothcd {
namespace {

using V = Eigen::Vector3d;
using Points = std::array<V, 8>;

struct CertifiedGen {
  std::mt19937_64 rng;
  explicit CertifiedGen(std::uint64_t seed) : rng(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(rng); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<>(lo, hi)(rng); }
  V vec(double s) { return V(uniform(-s, s), uniform(-s, s), uniform(-s, s)); }
};

// A contact parameter: well inside, or within 2^-k of the boundary value 0 (either side).
double parameter(CertifiedGen& g) {
  if (g.integer(0, 2) > 0) return g.uniform(0.1, 0.4);
  const double d = std::ldexp(1.0, -g.integer(5, 40));
  return g.integer(0, 1) == 0 ? d : -d;
}

// Contact time: anywhere, or within 2^-k of 0 or 1.
double contact_time(CertifiedGen& g) {
  if (g.integer(0, 2) > 0) return g.uniform(0.05, 0.95);
  const double d = std::ldexp(1.0, -g.integer(4, 30));
  return g.integer(0, 1) == 0 ? d : 1 - d;
}

Points planted_certified(CertifiedGen& g, bool vf) {
  const double s = std::ldexp(1.0, g.integer(-30, 30));
  const V shift = g.vec(s * std::ldexp(1.0, g.integer(0, 8)));
  Points p;
  for (int k = 1; k < 4; ++k) {
    p[k] = shift + g.vec(s);
    p[k + 4] = p[k] + g.vec(0.3 * s);
  }
  const double ts = contact_time(g);
  auto at = [&](int k) { return (1 - ts) * p[k] + ts * p[k + 4]; };
  const V w = g.vec(s);
  if (vf) {
    // The vertex crosses the face point with barycentric weights (1 - a - b, a, b) at ts.
    double a = parameter(g), b = parameter(g);
    if (g.integer(0, 1) == 0) a = 1 - a - b;  // near the hypotenuse too
    const V x = at(1) + a * (at(2) - at(1)) + b * (at(3) - at(1));
    p[0] = x - ts * w;
    p[4] = x + (1 - ts) * w;
  } else {
    // Edge a (points 0, 1) crosses point b of edge (2, 3) at its own parameter a, at ts.
    const double a = g.integer(0, 1) == 0 ? parameter(g) : 1 - parameter(g);
    const double b = g.integer(0, 1) == 0 ? parameter(g) : 1 - parameter(g);
    const V x = at(2) + b * (at(3) - at(2));
    const V e = g.vec(s);
    const V a0 = x - a * e, a1 = x + (1 - a) * e;
    const V w1 = g.vec(s);
    p[0] = a0 - ts * w;
    p[4] = a0 + (1 - ts) * w;
    p[1] = a1 - ts * w1;
    p[5] = a1 + (1 - ts) * w1;
  }
  // On a grid of s 2^-bits, so the exact rationals stay small for the oracle; the oracle decides
  // whether the rounded query still touches.
  const double cell = std::ldexp(s, -g.integer(20, 34));
  for (auto& x : p)
    x = (x / cell).array().round().matrix() * cell;
  return p;
}

bool exact(const Points& p, bool vf, double t_max = 1.0) {
  return vf ? test::exact_vertex_face_contact({p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]},
                                              t_max)
            : test::exact_edge_edge_contact({p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]},
                                            t_max);
}

CcdResult kernel(const Points& p, bool vf, const CcdOptions& opt) {
  return vf ? vertex_face_ccd({p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]}, opt)
            : edge_edge_ccd({p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]}, opt);
}

TEST(CcdCertified, CertifiedHitsAreRealAndEarly) {
  int certified = 0, positives = 0, tight = 0, queries = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    CertifiedGen g(seed);
    for (int i = 0; i < CLOTHCD_CCD_CERTIFIED_COUNT; ++i) {
      const bool vf = i % 2 == 0;
      const Points p = planted_certified(g, vf);
      const bool truth = exact(p, vf);
      ++queries;
      positives += truth;
      // The default toi tolerance and full refinement.
      for (double toi_tol : {1e-4, 0.0}) {
        CcdOptions opt;
        opt.toi_tolerance = toi_tol;
        const CcdResult r = kernel(p, vf, opt);
        const auto where = ::testing::Message()
                           << "seed " << seed << " #" << i << (vf ? " VF" : " EE") << " toi_tol "
                           << toi_tol << " toi " << r.toi;
        if (truth) {
          ASSERT_TRUE(r.hit) << "false negative: " << where;
        }
        if (r.hit && r.toi > 0) {
          ASSERT_FALSE(exact(p, vf, std::nextafter(r.toi, 0.0))) << "contact before toi: " << where;
        }
        if (r.path != CcdPath::Certified) continue;
        ASSERT_TRUE(r.hit) << where;
        ASSERT_TRUE(truth) << "certified hit without a contact: " << where;
        if (toi_tol > 0) {
          ++certified;
          // Usually (simple root) the first contact lies within one refinement range of the toi.
          tight += exact(p, vf, std::min(1.0, r.toi + std::ldexp(1.0, -13)));
        }
      }
    }
  }
  std::printf("%d queries, %d positive, %d certified, %d with the first contact within 2^-13\n",
              queries, positives, certified, tight);
  // The path is exercised: most planted contacts are transversal and well inside.
  EXPECT_GT(certified, positives / 3);
  EXPECT_GE(tight, certified * 9 / 10);
}

// Transversal contacts that are certain by construction (no rounding to a grid): well inside,
// at a random time; each must be certified, with a toi at most 2^-13 before the contact time.
TEST(CcdCertified, TransversalContactsAreCertified) {
  CertifiedGen g(77);
  int certified = 0, total = 0;
  for (int i = 0; i < 400; ++i) {
    const bool vf = i % 2 == 0;
    const double s = std::ldexp(1.0, g.integer(-30, 30));
    Points p;
    for (int k = 1; k < 4; ++k) {
      p[k] = g.vec(s);
      p[k + 4] = p[k];  // static face / edge b: the contact time is exactly ts
    }
    const double ts = g.uniform(0.1, 0.9);
    // Vertex / edge a moves along the face normal through an interior point.
    const V n = (p[2] - p[1]).cross(p[3] - p[1]);
    if (n.norm() < 1e-3 * s * s) continue;
    const V dir = n.normalized() * s;
    V x;
    if (vf) {
      x = p[1] + 0.3 * (p[2] - p[1]) + 0.3 * (p[3] - p[1]);
      p[0] = x - ts * dir;
      p[4] = x + (1 - ts) * dir;
    } else {
      x = p[2] + 0.5 * (p[3] - p[2]);
      const V e = (p[3] - p[2]).cross(n).normalized() * s;  // across edge b, in the plane
      for (int k : {0, 1}) {
        const V a = x + (k == 0 ? -0.5 : 0.5) * e;
        p[k] = a - ts * dir;
        p[k + 4] = a + (1 - ts) * dir;
      }
    }
    const CcdResult r = kernel(p, vf, {});
    ++total;
    ASSERT_TRUE(r.hit) << "#" << i;
    certified += r.path == CcdPath::Certified;
    // The contact is at ts up to the rounding of the construction.
    EXPECT_LE(r.toi, ts + 1e-9) << "#" << i;
    EXPECT_GE(r.toi, ts - std::ldexp(1.0, -13)) << "#" << i;
  }
  std::printf("%d transversal contacts, %d certified\n", total, certified);
  EXPECT_EQ(certified, total);
}

}  // namespace
}  // namespace clothcd
