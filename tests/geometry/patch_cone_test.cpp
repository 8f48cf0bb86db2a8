// Property tests of the patch cone (a node's cone from its triangles at once): it holds the true
// normal of every triangle of the patch at every sampled time, on smooth patches where it is
// narrow and on random ones where it mostly saturates.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

#include "clothcd/geometry/cone.hpp"
#include "cone_sampling.hpp"
#include "geometry/patch_block.hpp"
#include "geometry/patch_cone.hpp"
#include "support/isa_paths.hpp"

namespace clothcd::patch_cone_test {
namespace {

using test::kCases;
using test::Rng;
using test::to_ld;
using test::Vec3L;

struct Patch {
  std::vector<std::array<int, 3>> faces;
  std::vector<Eigen::Vector3d> x0, x1;
  std::vector<int> ids;
};

// A wavy strip of `n` triangles of size `size` around a random frame and place, moving by up to
// `motion` per vertex; with `spread`, each triangle's vertices also jitter by that much.
Patch random_patch(Rng& rng, int n, double size, double motion, double spread) {
  Patch p;
  const Eigen::Vector3d origin = rng.unit() * rng.log_uniform(1e-3, 1e3) * size;
  const Eigen::Vector3d u = rng.unit();
  const Eigen::Vector3d w = rng.perpendicular(u);
  const double wave = rng.uniform(0.0, 0.5);
  auto at = [&](double s, double r) {
    return Eigen::Vector3d(origin + size * (s * u + r * w + wave * std::sin(s) * u.cross(w)));
  };
  const int columns = n / 2 + 2;
  for (int c = 0; c < columns; ++c) {
    for (int r = 0; r < 2; ++r) {
      Eigen::Vector3d x = at(c, r) + spread * size * rng.unit();
      p.x0.push_back(x);
      p.x1.push_back(x + motion * size * rng.uniform() * rng.unit());
    }
  }
  for (int k = 0; k < n; ++k) {
    const int c = k / 2;
    const int a = 2 * c, b = 2 * c + 1, d = 2 * c + 2, e = 2 * c + 3;
    p.faces.push_back(k % 2 == 0 ? std::array<int, 3>{a, d, b} : std::array<int, 3>{b, d, e});
  }
  for (int k = 0; k < n; ++k)
    p.ids.push_back(n - 1 - k);  // any order of the ids
  return p;
}

// The normal of face f at time t in long double, and the angle its rounding may turn it by.
std::pair<Vec3L, long double> true_normal(const Patch& p, int f, long double t) {
  std::array<Vec3L, 3> x;
  for (int i = 0; i < 3; ++i) {
    const int v = p.faces[f][i];
    x[i] = (1 - t) * to_ld(p.x0[v]) + t * to_ld(p.x1[v]);
  }
  const Vec3L e1 = x[1] - x[0], e2 = x[2] - x[0];
  const Vec3L n = e1.cross(e2);
  const long double scale =
      e1.norm() * e2.norm() + (x[0].norm() + 1e-300L) * (e1.norm() + e2.norm());
  const long double err = 32 * std::numeric_limits<long double>::epsilon() * scale;
  const long double len = n.norm();
  return {n, len > err ? std::asin(err / len) : std::numbers::pi_v<long double>};
}

bool within(const NormalCone& c, const Vec3L& n, long double err) {
  const long double bound = c.half_angle + err;
  if (bound >= std::numbers::pi_v<long double> / 2) return true;
  const Vec3L a = to_ld(c.axis);
  const long double d = a.dot(n);
  return d > 0 && a.cross(n).norm() <= std::tan(bound) * d;
}

void expect_holds_every_normal(const Patch& p, const NormalCone& c, int seed) {
  ASSERT_TRUE(c.axis.allFinite() && std::isfinite(c.half_angle)) << "seed " << seed;
  ASSERT_NEAR(c.axis.norm(), 1.0, 1e-12) << "seed " << seed;
  if (c.saturated()) return;
  for (int f : p.ids) {
    for (int i = 0; i <= 32; ++i) {
      const auto [n, err] = true_normal(p, f, i / 32.0L);
      ASSERT_TRUE(within(c, n, err)) << "seed " << seed << " face " << f << " t " << i;
    }
  }
}

TEST(PatchCone, HoldsEveryNormalOfSmoothPatches) {
  int narrow = 0;
  const int cases = kCases / 20;
  for (int seed = 0; seed < cases; ++seed) {
    Rng rng(seed);
    const int n = rng.integer(1, 16);
    const Patch p = random_patch(rng, n, rng.log_uniform(1e-4, 1e2), rng.log_uniform(1e-9, 0.3),
                                 rng.chance(0.5) ? 0.0 : rng.log_uniform(1e-12, 0.1));
    const NormalCone c = detail::patch_ccd_cone(p.faces, p.ids, p.x0, p.x1);
    expect_holds_every_normal(p, c, seed);
    narrow += c.saturated() ? 0 : 1;
  }
  EXPECT_GT(narrow, cases / 2);  // most smooth patches must give a usable cone
}

// Every vector body of the per-triangle part computes the scalar body's bits, on smooth and
// random patches of every block size, at scales from tiny to huge (in_range false) and with
// degenerate triangles.
TEST(PatchCone, EveryVectorBodyMatchesTheScalarOne) {
  auto same = [](const detail::PatchBlock& a, const detail::PatchBlock& b, int count) {
    auto lanes = [&](const double* x, const double* y) {
      return std::memcmp(x, y, sizeof(double) * static_cast<std::size_t>(count)) == 0;
    };
    bool ok = lanes(a.r0, b.r0) && lanes(a.r1, b.r1) && lanes(a.rx, b.rx) &&
              lanes(a.in_range, b.in_range);
    for (int i = 0; i < 3; ++i) {
      ok = ok && lanes(a.q[i], b.q[i]);
      for (int d = 0; d < 3; ++d)
        ok = ok && lanes(a.n[i][d], b.n[i][d]) && lanes(a.unit[i][d], b.unit[i][d]);
    }
    return ok;
  };
  for (int seed = 0; seed < kCases / 20; ++seed) {
    Rng rng(seed);
    const int n = rng.integer(1, detail::PatchBlock::kLanes);
    const double size = rng.chance(0.1) ? rng.log_uniform(1e-90, 1e90) : rng.log_uniform(1e-4, 1e2);
    Patch p = random_patch(rng, n, size, rng.log_uniform(1e-9, 1.0),
                           rng.chance(0.5) ? 0.0 : rng.log_uniform(1e-12, 2.0));
    if (rng.chance(0.1)) p.x1[p.faces[0][1]] = p.x1[p.faces[0][0]];  // a triangle collapses
    detail::PatchBlock want, got;
    ASSERT_TRUE(detail::patch_block_with(0, p.faces.data(), p.ids.data(), n, p.x0.data(),
                                         p.x1.data(), want));
    for (int isa = 1; isa <= 3; ++isa) {
      const bool ran = detail::patch_block_with(isa, p.faces.data(), p.ids.data(), n, p.x0.data(),
                                                p.x1.data(), got);
      test::note_isa("patch_block", isa, ran);
      if (!ran) continue;
      ASSERT_TRUE(same(want, got, n)) << "isa " << isa << " seed " << seed;
    }
    detail::patch_block(p.faces.data(), p.ids.data(), n, p.x0.data(), p.x1.data(), got);
    test::note_isa("patch_block", 4, true);
    ASSERT_TRUE(same(want, got, n)) << "dispatch, seed " << seed;
  }
}

TEST(PatchCone, HoldsEveryNormalOfRandomPatches) {
  for (int seed = 0; seed < kCases / 20; ++seed) {
    Rng rng(seed);
    const Patch p = random_patch(rng, rng.integer(1, 8), 1.0, rng.log_uniform(1e-3, 3.0),
                                 rng.log_uniform(0.1, 2.0));
    expect_holds_every_normal(p, detail::patch_ccd_cone(p.faces, p.ids, p.x0, p.x1), seed);
  }
}

// A single triangle: no wider than the policies' leaf cones, up to the rounding allowance, and
// saturated where they are (its normal may vanish).
TEST(PatchCone, SingleTriangleIsNoWiderThanTheLeafCones) {
  for (int seed = 0; seed < kCases / 20; ++seed) {
    Rng rng(seed);
    const Patch p = random_patch(rng, 1, 1.0, rng.log_uniform(1e-6, 0.5), 0.0);
    const NormalCone c = detail::patch_ccd_cone(p.faces, p.ids, p.x0, p.x1);
    const auto& t = p.faces[0];
    const NormalCone tang = ccd_leaf_cone(p.x0[t[0]], p.x0[t[1]], p.x0[t[2]], p.x1[t[0]],
                                          p.x1[t[1]], p.x1[t[2]], LeafConePolicy::Tang);
    if (tang.saturated()) continue;
    ASSERT_LE(c.half_angle, 1.5 * tang.half_angle + 1e-9) << "seed " << seed;
  }
}

TEST(PatchCone, DegenerateTriangleSaturatesAndEmptyThrows) {
  Patch p;
  p.x0 = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0),
          Eigen::Vector3d(2, 0, 0)};
  p.x1 = p.x0;
  p.faces = {{0, 1, 2}, {0, 1, 3}};  // the second has no area
  const std::vector<int> good{0}, both{0, 1};
  EXPECT_FALSE(detail::patch_ccd_cone(p.faces, good, p.x0, p.x1).saturated());
  EXPECT_TRUE(detail::patch_ccd_cone(p.faces, both, p.x0, p.x1).saturated());
  // A patch folded flat onto itself has opposite normals.
  p.x0[3] = Eigen::Vector3d(0, -1, 0);
  p.x1 = p.x0;
  p.faces[1] = {0, 1, 3};
  EXPECT_TRUE(detail::patch_ccd_cone(p.faces, both, p.x0, p.x1).saturated());
  EXPECT_THROW(static_cast<void>(detail::patch_ccd_cone(p.faces, {}, p.x0, p.x1)),
               std::invalid_argument);
  p.x1[2].x() = std::nan("");
  EXPECT_THROW(static_cast<void>(detail::patch_ccd_cone(p.faces, good, p.x0, p.x1)),
               std::invalid_argument);
}

}  // namespace
}  // namespace clothcd::patch_cone_test
