// Strain figures and the strain limiter: a stretched sheet comes back within the limit, limited
// runs with collisions stay crossing-free, the limiter is bitwise deterministic, and its cheap
// within-the-limits test never spares a triangle that eig2 puts over a limit.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "clothcd/sim/integrator.hpp"
#include "clothcd/sim/scene.hpp"
#include "clothcd/sim/simulation.hpp"
#include "clothcd/sim/strain.hpp"
#include "grid.hpp"
#include "hash.hpp"
#include "sim/eig2.hpp"

namespace clothcd::sim {
namespace strain_test {

// Gram matrices F^T F of triangles whose principal stretches lie a relative 1e-15 to 1e-2 on
// either side of the limits, in every orientation: wherever certainly_within says yes, eig2's
// eigenvalues (what the limiter decides from) are within the limits; it says yes for most
// triangles clearly inside, and no for NaN.
TEST(StrainLimiter, WithinTestNeverSparesATriangleOverALimit) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586), sign(-1.0, 1.0);
  std::uniform_int_distribution<int> digits(2, 15);
  const double hi = 1.045, lo = 0.9;
  int spared = 0, inside_cases = 0, inside_spared = 0;
  for (int i = 0; i < 200000; ++i) {
    const double lo2 = (i % 2 == 0) ? 0.0 : lo * lo, hi2 = hi * hi;
    // Stretches near a limit (or one well inside for every tenth), a random rotation of them.
    const double near = std::pow(10.0, -digits(rng)) * sign(rng);
    const bool inside = i % 10 == 0;
    const double s1 = inside ? 1.02 : hi * (1.0 + near);
    const double s2 = inside ? 0.97 : (i % 4 < 2 ? lo * (1.0 + near) : 1.0);
    const double t = angle(rng);
    Mat2 r;
    r << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
    const Mat2 c = r * Eigen::Vector2d(s1 * s1, s2 * s2).asDiagonal() * r.transpose();
    inside_cases += inside ? 1 : 0;
    if (!detail::certainly_within(c, lo2, hi2)) continue;
    ++spared;
    const detail::Eig2 e = detail::eig2(c);
    ASSERT_LE(e.l1, hi2) << "stretches " << s1 << ", " << s2;
    if (lo2 > 0.0) {
      ASSERT_GE(e.l2, lo2) << "stretches " << s1 << ", " << s2;
    }
    inside_spared += inside ? 1 : 0;
  }
  EXPECT_GT(spared, inside_spared);        // some near the limits too
  EXPECT_EQ(inside_spared, inside_cases);  // 2% and 3% from the limits: always spared
  Mat2 nan = Mat2::Identity();
  nan(0, 1) = nan(1, 0) = std::nan("");
  EXPECT_FALSE(detail::certainly_within(nan, 0.0, hi * hi));
  EXPECT_FALSE(detail::certainly_within(Mat2::Identity() * (hi * hi), 0.0, hi * hi));
}

using test::grid_cloth;

// A sheet stretched by `factor` along x (and a little noise), as positions.
std::vector<Vec3> stretched(const ClothModel& m, double factor, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::vector<Vec3> x = m.initial_positions();
  for (Vec3& p : x) {
    p.x() *= factor;
    p += test::random_vec(rng, 1e-4);
  }
  return x;
}

double largest(const std::vector<double>& s) {
  return *std::max_element(s.begin(), s.end());
}

TEST(Strain, FiguresOfAUniformStretch) {
  const ClothModel m(grid_cloth(10, 10, 0.2, 0.2), ClothMaterial{});
  std::vector<Vec3> x = m.initial_positions();
  for (Vec3& p : x)
    p.x() *= 1.2;
  const StrainFigures f = strain_figures(m, x, {});
  EXPECT_NEAR(f.median, 0.2, 1e-12);
  EXPECT_NEAR(f.p99, 0.2, 1e-12);
  EXPECT_NEAR(f.max, 0.2, 1e-12);
  EXPECT_EQ(f.over_10, 1.0);
  EXPECT_EQ(f.max_site, StrainSite::Elsewhere);
  // At rest: no strain; a rigid rotation changes nothing.
  const Eigen::AngleAxisd rot(0.7, Vec3(1, 2, 3).normalized());
  std::vector<Vec3> r = m.initial_positions();
  for (Vec3& p : r)
    p = rot * p;
  EXPECT_LT(strain_figures(m, r, {}).max, 1e-12);
}

TEST(Strain, WorstTriangleSiteIsReported) {
  ClothMeshInput in = grid_cloth(6, 6, 0.1, 0.1);
  in.stitches.push_back({0, 1, 2, 0.5});
  const ClothModel m(in, ClothMaterial{});
  std::vector<Vec3> x = m.initial_positions();
  const std::vector<double> s0 = triangle_strains(m, x);
  EXPECT_LT(largest(s0), 1e-12);
  // Stretch the triangle at the far corner (no stitch there): first elsewhere, then, with its
  // vertex flagged, body contact.
  const int far = static_cast<int>(x.size()) - 1;
  x[far].x() += 0.01;
  StrainFigures f = strain_figures(m, x, {});
  EXPECT_EQ(f.max_site, StrainSite::Elsewhere);
  std::vector<std::uint8_t> contact(x.size(), 0);
  contact[far] = 1;
  f = strain_figures(m, x, contact);
  EXPECT_EQ(f.max_site, StrainSite::BodyContact);
  const Face& t = m.topology().faces()[f.max_face];
  EXPECT_TRUE(t[0] == far || t[1] == far || t[2] == far);
  // A stretched triangle at the stitch: seam.
  x = m.initial_positions();
  x[0].x() -= 0.01;
  EXPECT_EQ(strain_figures(m, x, {}).max_site, StrainSite::Seam);
}

TEST(StrainLimiter, PulledSheetComesBackWithinTheLimit) {
  ClothMaterial mat;
  mat.strain_limit = 1.05;
  const ClothModel m(grid_cloth(24, 16, 0.24, 0.16), mat);
  StrainLimiter limiter(m);
  ASSERT_TRUE(limiter.enabled());
  const std::vector<Vec3> target = stretched(m, 1.3, 1);
  ASSERT_GT(largest(triangle_strains(m, target)), 0.29);
  // The velocities that would reach the stretched sheet from rest in h.
  const double h = 0.01;
  const std::vector<Vec3> x0 = m.initial_positions();
  std::vector<Vec3> v(x0.size());
  for (std::size_t i = 0; i < x0.size(); ++i)
    v[i] = (target[i] - x0[i]) / h;
  const std::vector<double> inverse_mass(x0.size(), 1.0);
  const Vec3 p0 = [&] {
    Vec3 p = Vec3::Zero();
    for (std::size_t i = 0; i < v.size(); ++i)
      p += m.mass()[i] * v[i];
    return p;
  }();
  const StrainLimitStats st = limiter.apply(x0, h, inverse_mass, {}, v, 500);
  EXPECT_GT(st.projections, 0);
  std::vector<Vec3> x1(x0.size());
  Vec3 p1 = Vec3::Zero();
  for (std::size_t i = 0; i < x0.size(); ++i) {
    x1[i] = x0[i] + h * v[i];
    p1 += m.mass()[i] * v[i];
  }
  EXPECT_LT(largest(triangle_strains(m, x1)), 0.05 + 1e-3);
  // Projections about mass-weighted centroids keep the linear momentum.
  EXPECT_LT((p1 - p0).norm(), 1e-9 * p0.norm());
}

TEST(StrainLimiter, CompressionLimitAndPinnedVertices) {
  ClothMaterial mat;
  mat.strain_limit = 0.0;
  mat.compression_limit = 0.9;
  const ClothModel m(grid_cloth(12, 12, 0.12, 0.12), mat);
  StrainLimiter limiter(m);
  const std::vector<Vec3> x0 = m.initial_positions();
  std::vector<Vec3> v(x0.size(), Vec3::Zero());
  const double h = 0.01;
  for (std::size_t i = 0; i < x0.size(); ++i)
    v[i].x() = -0.3 * x0[i].x() / h;  // squeezed to 70% along x
  std::vector<double> inverse_mass(x0.size(), 1.0);
  inverse_mass[0] = 0.0;  // pinned: does not move
  limiter.apply(x0, h, inverse_mass, {}, v, 500);
  EXPECT_EQ(v[0], Vec3(0.0, 0.0, 0.0));
  // Smallest principal stretch back to >= 0.9 (largest stretch at most 1 + tolerance).
  const auto& faces = m.topology().faces();
  for (int f = 0; f < m.topology().num_faces(); ++f) {
    const Face& t = faces[f];
    const Vec3 e1 = x0[t[1]] + h * v[t[1]] - x0[t[0]] - h * v[t[0]];
    const Vec3 e2 = x0[t[2]] + h * v[t[2]] - x0[t[0]] - h * v[t[0]];
    const double area = 0.5 * e1.cross(e2).norm();
    EXPECT_GT(area, 0.88 * 0.88 * m.membrane_rest()[f].area) << "face " << f;
  }
}

// Inside the collision stage the limiter holds the vertices a CCD projection stopped (inverse
// mass 0 there): they keep their motion, and their neighbours follow them back within the limit.
TEST(StrainLimiter, HeldVertexKeepsItsMotionAndItsNeighboursFollow) {
  ClothMaterial mat;
  mat.strain_limit = 1.05;
  const ClothModel m(grid_cloth(16, 16, 0.16, 0.16), mat);
  StrainLimiter limiter(m);
  const std::vector<Vec3> x0 = m.initial_positions();
  const double h = 0.01;
  // Everything moves 1 cm along z but the centre vertex, which a projection stopped.
  std::vector<Vec3> v(x0.size(), Vec3(0.0, 0.0, 1.0));
  const int held = 8 * 17 + 8;
  v[held] = Vec3::Zero();
  auto ends = [&] {
    std::vector<Vec3> x(x0.size());
    for (std::size_t i = 0; i < x0.size(); ++i)
      x[i] = x0[i] + h * v[i];
    return x;
  };
  ASSERT_GT(largest(triangle_strains(m, ends())), 0.3);
  std::vector<double> inverse_mass(x0.size(), 1.0);
  inverse_mass[held] = 0.0;
  std::vector<std::uint8_t> start(x0.size(), 0);
  start[held] = 1;  // only the triangles around it are checked first
  const StrainLimitStats st = limiter.apply(x0, h, inverse_mass, {}, v, 200, start);
  EXPECT_GT(st.projections, 0);
  EXPECT_EQ(v[held], Vec3(0.0, 0.0, 0.0));
  EXPECT_LT(largest(triangle_strains(m, ends())), 0.05 + 1e-3);
  // Its neighbours were dragged back towards it; far corners kept moving.
  EXPECT_LT(v[held + 1].z(), 0.9);
  EXPECT_EQ(v[0], Vec3(0.0, 0.0, 1.0));
  // Only what moved is reported.
  EXPECT_EQ(limiter.moved()[0], 0);
  EXPECT_EQ(limiter.moved()[held + 1], 1);
}

TEST(StrainLimiter, BitwiseDeterministicAcrossThreadCounts) {
  ClothMaterial mat;
  mat.strain_limit = 1.04;
  const ClothModel m(grid_cloth(60, 40, 0.6, 0.4), mat);
  const std::vector<Vec3> x0 = m.initial_positions();
  const std::vector<Vec3> target = stretched(m, 1.25, 7);
  const double h = 0.005;
  std::vector<Vec3> v0(x0.size());
  for (std::size_t i = 0; i < x0.size(); ++i)
    v0[i] = (target[i] - x0[i]) / h;
  const std::vector<double> inverse_mass(x0.size(), 1.0);
  std::vector<std::uint64_t> hashes;
  for (int threads : {1, 2, 4}) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      StrainLimiter limiter(m);
      std::vector<Vec3> v = v0;
      limiter.apply(x0, h, inverse_mass, {}, v, 8);
      // A second call as in the collision stage: from flagged vertices, some held, some on a
      // support plane (continuing where the first stopped).
      std::vector<std::uint8_t> start(x0.size(), 0);
      std::vector<double> held = inverse_mass;
      std::vector<Vec3> support(x0.size(), Vec3::Zero());
      for (std::size_t i = 0; i < x0.size(); i += 7) {
        start[i] = 1;
        if (i % 3 == 0) held[i] = 0.0;
        if (i % 5 == 0) support[i] = Vec3::UnitY();
        v[i] *= 1.5;
      }
      limiter.apply(x0, h, held, support, v, 4, start);
      hashes.push_back(test::hash_positions(v));
    });
  }
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_EQ(hashes[0], hashes[2]);
}

// A soft sheet held by one edge falls onto a sphere: without the limit its weight stretches it
// by tens of percent; with it the limit holds, and the collision stage keeps every frame free of
// crossings.
std::string held_sheet_scene(double limit) {
  return R"({
    "name": "held-sheet", "frames": 15, "frame_dt": 0.02,
    "cloth": {"grid": {"origin": [-0.1, 0.25, -0.25], "u": [0.5, 0, 0], "v": [0, 0, 0.5],
                       "resolution": [20, 20]}},
    "material": {"stretch_stiffness": 3, "strain_limit": )" +
         std::to_string(limit) + R"(},
    "body": {"type": "sphere", "center": [0, 0, 0], "radius": 0.2, "subdivisions": 3},
    "pins": [{"grid_edge": "u0"}],
    "solver": {"strain_sweeps": 100},
    "collisions": {"thickness": 0.002}
  })";
}

TEST(StrainLimiter, LimitedRunStaysCrossingFreeAndWithinTheLimit) {
  auto run = [](double limit, int threads) {
    tbb::task_arena arena(threads);
    std::vector<FrameStats> frames;
    std::uint64_t hash = 0;
    arena.execute([&] {
      Simulation sim(parse_scene_text(held_sheet_scene(limit), "held.json"));
      for (int k = 0; k < sim.scene().frames; ++k)
        frames.push_back(sim.advance_frame());
      hash = test::hash_positions(sim.state().x);
    });
    return std::pair{frames, hash};
  };
  const auto [free_frames, free_hash] = run(0.0, 2);
  const auto [limited, hash2] = run(1.05, 2);
  const auto [limited1, hash1] = run(1.05, 1);
  EXPECT_EQ(hash1, hash2);
  double free_p99 = 0.0, limited_p99 = 0.0;
  for (const FrameStats& f : free_frames)
    free_p99 = std::max(free_p99, f.strain.p99);
  for (const FrameStats& f : limited)
    limited_p99 = std::max(limited_p99, f.strain.p99);
  EXPECT_GT(free_p99, 0.2);  // without the limit, the weight stretches the sheet
  // Within the limit while the sheet hangs (frames 1-5); on the sphere, where the collision stage
  // stops vertices in the later CCD passes, a few percent more.
  EXPECT_LT(limited_p99, 0.1);
  for (const FrameStats& f : limited) {
    EXPECT_EQ(f.self_intersections, 0) << "frame " << f.frame;
    EXPECT_EQ(f.body_intersections, 0) << "frame " << f.frame;
    EXPECT_EQ(f.collision.unresolved, 0) << "frame " << f.frame;
    if (f.frame <= 5) {
      EXPECT_LT(f.strain.p99, 0.05 + 1e-3) << "frame " << f.frame;
    }
  }
}

}  // namespace strain_test
}  // namespace clothcd::sim
