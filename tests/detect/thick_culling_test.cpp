// Sound cone culling with a contact thickness (docs/algorithms.md 1.6) against the brute force,
// on exact pair sets: scenes where it culls, and adversarial patches whose features come within
// the thickness although their cones are narrow and their projections injective.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "clothcd/detect/detector.hpp"
#include "clothcd/research/oracle.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd {
namespace {

// A grid of nu x nv quads over (u, v) in [0, 1]^2, each split into two triangles, with vertex
// positions map(u, v) at t0 and map(u, v) + motion(u, v) at t1.
using Map = std::function<Eigen::Vector3d(double, double)>;
research::ProceduralScene grid(const char* name, int nu, int nv, const Map& at_t0,
                               const Map& at_t1) {
  research::ProceduralScene s;
  s.name = name;
  s.num_vertices = (nu + 1) * (nv + 1);
  s.v_t0.resize(s.num_vertices, 3);
  s.v_t1.resize(s.num_vertices, 3);
  auto id = [&](int i, int j) { return j * (nu + 1) + i; };
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const double u = double(i) / nu, v = double(j) / nv;
      s.v_t0.row(id(i, j)) = at_t0(u, v).transpose();
      s.v_t1.row(id(i, j)) = at_t1(u, v).transpose();
    }
  }
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      s.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return s;
}

// Runs Sound (both builds, every sound policy) against the brute force with the same options and
// returns the nodes culled.
std::uint64_t expect_sound_equals_brute_force(const research::ProceduralScene& s,
                                              double thickness) {
  const Topology topo(s.faces, s.num_vertices);
  DetectOptions o;
  o.thickness = thickness;
  const DetectResult ref = research::brute_force_detect(topo, s.v_t0, s.v_t1, o);
  std::uint64_t culled = 0;
  for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
    for (ConePolicy policy : {ConePolicy::Provot, ConePolicy::Proposed, ConePolicy::Exact}) {
      SCOPED_TRACE(::testing::Message() << s.name << " thickness " << thickness << " build "
                                        << int(build) << " policy " << int(policy));
      o.build = build;
      o.policy = policy;
      o.culling = Culling::Sound;
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      const DetectResult r = det.detect(s.v_t0, s.v_t1);
      EXPECT_EQ(r.vf, ref.vf);
      EXPECT_EQ(r.ee, ref.ee);
      culled += r.stats.nodes_culled;
    }
  }
  return culled;
}

// A gently waving sheet moving a little: the rule should cull most of it, and lose nothing.
TEST(ThickSoundCulling, CullsAWavingSheetAndEqualsBruteForce) {
  auto wave = [](double phase) {
    return [phase](double u, double v) {
      return Eigen::Vector3d(u, v, 0.05 * std::sin(6 * u + phase) * std::cos(5 * v));
    };
  };
  const research::ProceduralScene s = grid("waving sheet", 24, 24, wave(0.0), wave(0.3));
  for (double h : {1e-5, 1e-3}) {
    EXPECT_GT(expect_sound_equals_brute_force(s, h), 0u) << "thickness " << h;
  }
}

// A flat C-shaped strip (an annulus sector) whose two ends are `gap` apart: every cone is a
// point, the projection is injective and the contour simple, yet the ends are within the
// thickness when gap < h. Only the contour clearance can refuse the cull.
TEST(ThickSoundCulling, NearlyClosedFlatRingIsNotCulledAcrossItsGap) {
  const double gap = 2e-3;
  auto ring = [gap](double lift) {
    return [gap, lift](double u, double v) {
      const double r = 1.0 + 0.2 * v;
      const double angle = u * (2 * std::numbers::pi - gap);  // the ends are about gap apart
      return Eigen::Vector3d(r * std::cos(angle), r * std::sin(angle), lift);
    };
  };
  const research::ProceduralScene s = grid("nearly closed ring", 64, 2, ring(0.0), ring(1e-4));
  const Topology topo(s.faces, s.num_vertices);
  DetectOptions o;
  o.thickness = 5e-3;
  const DetectResult ref = research::brute_force_detect(topo, s.v_t0, s.v_t1, o);
  ASSERT_GT(ref.vf.size() + ref.ee.size(), 0u);  // the ends are within the thickness
  static_cast<void>(expect_sound_equals_brute_force(s, 5e-3));
  // Farther than the thickness: the same patches may be culled, and still nothing is lost.
  EXPECT_GT(expect_sound_equals_brute_force(s, 1e-4), 0u);
}

// A helical ramp: one turn, rising `pitch` per turn, so its projection along the axis nearly
// closes on itself while in 3-D the turn's ends are `pitch` apart. Its cone is narrow (the ramp
// is gentle) and its projection barely injective.
TEST(ThickSoundCulling, BarelyInjectiveRampEqualsBruteForce) {
  const double pitch = 0.01;
  auto ramp = [pitch](double shift) {
    return [pitch, shift](double u, double v) {
      const double r = 1.0 + 0.2 * v;
      const double angle = u * (2 * std::numbers::pi - 1e-3);
      return Eigen::Vector3d(r * std::cos(angle), r * std::sin(angle), pitch * u + shift);
    };
  };
  const research::ProceduralScene s = grid("helical ramp", 64, 2, ramp(0.0), ramp(2e-4));
  for (double h : {1e-3, 2e-2})
    static_cast<void>(expect_sound_equals_brute_force(s, h));
}

// Two layers folded onto each other: a strip bent through pi about a crease so that its halves
// lie `gap` apart, the gap below the thickness; and a fine mesh whose triangles are lower than
// the thickness (the corner clearance must refuse it).
TEST(ThickSoundCulling, FoldedLayersAndFineMeshesEqualBruteForce) {
  const double gap = 1e-3;
  auto fold = [gap](double close) {
    return [gap, close](double u, double v) {
      // u in [0, 0.45]: lower layer; [0.45, 0.55]: a half-turn of radius gap / 2; then upper.
      const double radius = 0.5 * gap * close;
      if (u < 0.45) return Eigen::Vector3d(u, v, 0.0);
      if (u > 0.55) return Eigen::Vector3d(0.45 - (u - 0.55), v, 2 * radius);
      const double a = (u - 0.45) / 0.1 * std::numbers::pi;
      return Eigen::Vector3d(0.45 + radius * std::sin(a), v, radius * (1 - std::cos(a)));
    };
  };
  const research::ProceduralScene folded = grid("folded layers", 24, 3, fold(1.0), fold(0.8));
  static_cast<void>(expect_sound_equals_brute_force(folded, 2e-3));
  auto flat = [](double z) { return [z](double u, double v) { return Eigen::Vector3d(u, v, z); }; };
  const research::ProceduralScene fine = grid("fine mesh", 12, 12, flat(0.0), flat(1e-4));
  static_cast<void>(expect_sound_equals_brute_force(fine, 0.1));  // triangles 0.083 high
}

// An interior vertex pushed to within 1e-4 of an edge of its own 1-ring, far from the patch's
// boundary: the contour is clear, so only the corner clearance can refuse the cull.
TEST(ThickSoundCulling, InteriorSliverIsNotCulled) {
  auto flat = [](double z) { return [z](double u, double v) { return Eigen::Vector3d(u, v, z); }; };
  research::ProceduralScene s = grid("interior sliver", 16, 16, flat(0.0), flat(1e-5));
  // Vertex (8, 8) sits at (0.5, 0.5); its 1-ring includes the edge from (9, 8) to (9, 9), the
  // line u = 9/16. Move it to 1e-4 short of that line.
  const int v = 8 * 17 + 8;
  for (Positions* x : {&s.v_t0, &s.v_t1})
    (*x)(v, 0) = 9.0 / 16 - 1e-4;
  const Topology topo(s.faces, s.num_vertices);
  DetectOptions o;
  o.thickness = 1e-3;
  const DetectResult ref = research::brute_force_detect(topo, s.v_t0, s.v_t1, o);
  ASSERT_GT(ref.vf.size() + ref.ee.size(), 0u);  // the vertex is within the thickness
  static_cast<void>(expect_sound_equals_brute_force(s, 1e-3));
}

}  // namespace
}  // namespace clothcd
