// Sewn garments: the patch BVH keeps at least 99% of its
// internal nodes edge-connected; on a step from the drape to a smoothly perturbed pose the sound
// culling finds exactly what the unculled traversal finds in every policy and build, and on the
// dress it culls at least half as many triangle pairs as the paper's cone-only rule; with the
// simulator's thickness and proximity reuse it stays exact, the query after it included.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>

#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/sewing.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/options.hpp"
#include "clothcd/research/procedural.hpp"
#include "support/data.hpp"

namespace clothcd {
// A namespace of its own: the research types below stay in this file of the unity build.
namespace garment_test {

// The research detector and options (unsound rules, optimal cones, verification).
using research::DetectOptions;
using research::SelfDetector;

struct Garment {
  TriangleMesh sewn;
  Positions p0, p1;
};

// The garment prefix of a drape.obj, sewn at 0.1 mm, and a step to a smooth perturbation of
// `amplitude` (wavelength 0.1 m): the `clothcd detect --garment-vertices N --sew 1e-4 --perturb A
// --wavelength 0.1` step.
Garment load(const std::filesystem::path& obj, int vertices, int faces, double amplitude) {
  const TriangleMesh drape = read_obj(obj);
  const TriangleMesh garment = submesh_prefix(drape, vertices, faces);
  const SewnMesh sewn = sew(garment, 1e-4);
  EXPECT_EQ(sewn.report.components_after, 1);
  Garment g;
  g.sewn = sewn.mesh;
  const Positions moved =
      research::smooth_perturbation(vertices_matrix(garment), amplitude, 0.1, 1);
  // Each sewn vertex takes the position of its smallest original id (as weld does).
  g.p0 = vertices_matrix(g.sewn);
  g.p1 = g.p0;
  std::vector<int> first(g.sewn.num_vertices(), -1);
  for (int i = static_cast<int>(sewn.vertex_map.size()) - 1; i >= 0; --i)
    first[sewn.vertex_map[i]] = i;
  for (int n = 0; n < g.sewn.num_vertices(); ++n)
    g.p1.row(n) = moved.row(first[n]);
  return g;
}

double culled_share(const DetectResult& r, const DetectResult& none) {
  return 1.0 - double(r.stats.triangle_pairs) / double(none.stats.triangle_pairs);
}

TEST(Garments, DressPatchConnectedAndSoundCullsHalfOfCone) {
  CLOTHCD_REQUIRE_DATA(root, "garments/dress_knife/drape.obj");
  const Garment g = load(root, 15656, 29456, 0.01);
  const ConePolicy policies[] = {ConePolicy::Provot, ConePolicy::Proposed, ConePolicy::Exact};
  // Per policy: the share of triangle pairs culled by `cone` (best build) and by `sound` (patch).
  double cone_best[3] = {0, 0, 0}, sound_patch[3] = {0, 0, 0};
  std::size_t collisions = 0;
  for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
    DetectOptions o;
    o.build = build;
    SelfDetector det(g.sewn.faces, g.sewn.num_vertices(), g.p0, o);
    const DetectResult none = det.detect(g.p0, g.p1);
    collisions = none.vf.size() + none.ee.size();
    EXPECT_GT(collisions, 0u) << "the step must collide to test anything";
    if (build == BvhBuild::Patch) {
      EXPECT_GE(none.stats.connected_share(), 0.99);
    }
    for (int k = 0; k < 3; ++k) {
      SCOPED_TRACE(::testing::Message() << "build " << int(build) << " policy " << k);
      o.policy = policies[k];
      o.culling = Culling::Sound;
      o.research = {};  // the cone rule of the previous policy off
      o.research.verify = true;
      det.set_options(o);
      const research::DetectResult sound = det.detect(g.p0, g.p1);
      ASSERT_TRUE(sound.verification.ran);
      EXPECT_TRUE(sound.verification.missed_vf.empty());
      EXPECT_TRUE(sound.verification.missed_ee.empty());
      EXPECT_EQ(sound.vf, none.vf);
      EXPECT_EQ(sound.ee, none.ee);
      o.research.culling = research::CullingRule::Cone;
      o.research.verify = false;
      det.set_options(o);
      const DetectResult cone = det.detect(g.p0, g.p1);
      cone_best[k] = std::max(cone_best[k], culled_share(cone, none));
      if (build == BvhBuild::Patch) sound_patch[k] = culled_share(sound, none);
    }
  }
  for (int k = 0; k < 3; ++k) {
    std::printf(
        "policy %d: sound/patch culls %.2f%% of the triangle pairs, cone (best build) %.2f%%\n", k,
        100 * sound_patch[k], 100 * cone_best[k]);
    EXPECT_GT(cone_best[k], 0.0);
    EXPECT_GE(sound_patch[k], 0.5 * cone_best[k]) << "policy " << k;
  }
}

TEST(Garments, MultilayerPatchConnectedAndSoundExact) {
  CLOTHCD_REQUIRE_DATA(root, "garments/multilayer/drape.obj");
  const Garment g = load(root, 30464, 58687, 0.01);
  DetectOptions o;
  o.build = BvhBuild::Patch;
  o.policy = ConePolicy::Proposed;
  o.culling = Culling::Sound;
  o.research.verify = true;
  SelfDetector det(g.sewn.faces, g.sewn.num_vertices(), g.p0, o);
  const research::DetectResult r = det.detect(g.p0, g.p1);
  EXPECT_GE(r.stats.connected_share(), 0.99);
  const research::Verification& v = r.verification;
  ASSERT_TRUE(v.ran);
  EXPECT_GT(r.vf.size() + r.ee.size() + v.missed_vf.size() + v.missed_ee.size(), 0u);
  EXPECT_TRUE(v.missed_vf.empty());
  EXPECT_TRUE(v.missed_ee.empty());
}

// The simulator's settings on the dress: a CCD thickness, pairs kept for a proximity query at a
// reuse distance, a substep-sized step (2 mm). Sound culling under each policy reports exactly
// what the unculled traversal reports, and the query after it (at the step's end, then with a
// patch of vertices moved) exactly what an unculled detector without reuse finds, distances
// included.
TEST(Garments, DressSoundWithThicknessAndReuseExact) {
  CLOTHCD_REQUIRE_DATA(root, "garments/dress_knife/drape.obj");
  const Garment g = load(root, 15656, 29456, 0.002);
  const double reuse = 1e-3;
  DetectOptions plain;
  plain.thickness = 1e-5;
  plain.build = BvhBuild::Patch;
  SelfDetector ref(g.sewn.faces, g.sewn.num_vertices(), g.p0, plain);
  Positions shifted = g.p1;
  for (Eigen::Index i = 0; i < shifted.rows(); i += 7)
    shifted(i, 1) += 3e-4;
  const ProximityResult ref_end = ref.proximity(g.p1, reuse);
  const ProximityResult ref_shifted = ref.proximity(shifted, reuse);
  ASSERT_GT(ref_end.vf.size() + ref_end.ee.size(), 0u);
  std::uint64_t culled = 0;
  for (ConePolicy policy : {ConePolicy::Provot, ConePolicy::Proposed}) {
    SCOPED_TRACE(::testing::Message() << "policy " << int(policy));
    DetectOptions o = plain;
    o.culling = Culling::Sound;
    o.policy = policy;
    o.reuse_distance = reuse;
    o.research.verify = true;
    SelfDetector det(g.sewn.faces, g.sewn.num_vertices(), g.p0, o);
    const research::DetectResult r = det.detect(g.p0, g.p1);
    ASSERT_TRUE(r.verification.ran);
    EXPECT_TRUE(r.verification.missed_vf.empty());
    EXPECT_TRUE(r.verification.missed_ee.empty());
    culled += r.stats.nodes_culled;
    for (const Positions* at : std::array<const Positions*, 2>{&g.p1, &shifted}) {
      static_cast<void>(det.detect(g.p0, g.p1));
      const ProximityResult p = det.proximity(*at, reuse);
      const ProximityResult& want = at == &g.p1 ? ref_end : ref_shifted;
      EXPECT_GT(p.reused_pairs, 0u);
      EXPECT_EQ(p.vf, want.vf);
      EXPECT_EQ(p.ee, want.ee);
    }
  }
  EXPECT_GT(culled, 0u);  // the cones were in the loop
}

// The simulator's cone threshold (DetectOptions::cull_min_triangles) on the dress with its CCD
// thickness and reuse distance: under each policy, the same collisions as no culling and the same
// proximity query after it, with cones refit and tested on the large nodes only.
TEST(Garments, DressCullThresholdSameResults) {
  CLOTHCD_REQUIRE_DATA(root, "garments/dress_knife/drape.obj");
  const Garment g = load(root, 15656, 29456, 0.002);
  const double reuse = 1e-3;
  DetectOptions o;
  o.thickness = 1e-5;
  o.build = BvhBuild::Patch;
  o.reuse_distance = reuse;
  SelfDetector none(g.sewn.faces, g.sewn.num_vertices(), g.p0, o);
  const DetectResult want = none.detect(g.p0, g.p1);
  const ProximityResult want_near = none.proximity(g.p1, reuse);
  ASSERT_GT(want.vf.size() + want.ee.size(), 0u);
  for (ConePolicy policy : {ConePolicy::Provot, ConePolicy::Proposed}) {
    std::uint64_t culled[2] = {0, 0};
    for (const int min : {0, 16}) {
      SCOPED_TRACE(::testing::Message() << "policy " << int(policy) << " min " << min);
      DetectOptions c = o;
      c.culling = Culling::Sound;
      c.policy = policy;
      c.cull_min_triangles = min;
      SelfDetector det(g.sewn.faces, g.sewn.num_vertices(), g.p0, c);
      const research::DetectResult r = det.detect(g.p0, g.p1);
      EXPECT_EQ(r.vf, want.vf);
      EXPECT_EQ(r.ee, want.ee);
      culled[min > 0 ? 1 : 0] = r.stats.nodes_culled;
      const ProximityResult p = det.proximity(g.p1, reuse);
      EXPECT_EQ(p.vf, want_near.vf);
      EXPECT_EQ(p.ee, want_near.ee);
    }
    EXPECT_GT(culled[0], 0u);
    EXPECT_GT(culled[1], 0u);  // the large nodes still cull
  }
}

// A simulator's sequence on the dress with sound culling and pairs kept for reuse: a full pass
// (its nodes culled at the kernels' reach over the step and at the reuse distance at its end), a
// restricted pass (the active vertices moved again), the proximity query (the kept pairs and the
// moved vertices' traversal), then a rebuilt tree, with and without linked vertices. Every pass
// and query equals a detector without culling or reuse, pair for pair and distance for
// distance.
TEST(Garments, DressSoundReuseSequenceEqualsNone) {
  CLOTHCD_REQUIRE_DATA(root, "garments/dress_knife/drape.obj");
  const Garment g = load(root, 15656, 29456, 0.002);
  const double reuse = 1e-3;
  std::vector<int> active;
  Positions later = g.p1;
  for (int v = 0; v < static_cast<int>(later.rows()); v += 11) {
    active.push_back(v);
    later(v, 1) += 2e-4;
  }
  // Links between close vertex-face pairs of the step's end, as stitches would make them.
  std::vector<std::pair<int, int>> links;
  {
    DetectOptions plain;
    plain.build = BvhBuild::Patch;
    SelfDetector probe(g.sewn.faces, g.sewn.num_vertices(), g.p0, plain);
    const ProximityResult near = probe.proximity(g.p1, reuse);
    for (std::size_t i = 0; i < near.vf.size(); i += 3)
      links.emplace_back(near.vf[i].vertex, g.sewn.faces[near.vf[i].face][0]);
    ASSERT_FALSE(links.empty());
  }
  std::uint64_t culled = 0, reused = 0, culled_pairs = 0;
  for (const bool linked : {false, true}) {
    DetectOptions plain;
    plain.thickness = 1e-5;
    plain.build = BvhBuild::Patch;
    if (linked) plain.linked_vertices = links;
    for (ConePolicy policy : {ConePolicy::Provot, ConePolicy::Proposed}) {
      SCOPED_TRACE(::testing::Message() << "linked " << linked << " policy " << int(policy));
      DetectOptions o = plain;
      o.culling = Culling::Sound;
      o.policy = policy;
      o.reuse_distance = reuse;
      SelfDetector det(g.sewn.faces, g.sewn.num_vertices(), g.p0, o);
      SelfDetector ref(g.sewn.faces, g.sewn.num_vertices(), g.p0, plain);
      const DetectResult full = det.detect(g.p0, g.p1);
      const DetectResult full_ref = ref.detect(g.p0, g.p1);
      EXPECT_EQ(full.vf, full_ref.vf);
      EXPECT_EQ(full.ee, full_ref.ee);
      EXPECT_LT(full.stats.triangle_pairs, full_ref.stats.triangle_pairs);
      culled += full.stats.nodes_culled;
      culled_pairs += full_ref.stats.triangle_pairs - full.stats.triangle_pairs;
      det.set_active_vertices(active);
      ref.set_active_vertices(active);
      const DetectResult part = det.detect(g.p1, later);
      const DetectResult part_ref = ref.detect(g.p1, later);
      EXPECT_EQ(part.vf, part_ref.vf);
      EXPECT_EQ(part.ee, part_ref.ee);
      det.clear_active();
      ref.clear_active();
      for (const Positions* at : std::array<const Positions*, 2>{&g.p1, &later}) {
        const ProximityResult p = det.proximity(*at, reuse);
        const ProximityResult p_ref = ref.proximity(*at, reuse);
        EXPECT_GT(p.reused_pairs, 0u);
        reused += p.reused_pairs;
        EXPECT_EQ(p.vf, p_ref.vf);
        EXPECT_EQ(p.ee, p_ref.ee);
      }
      // A rebuilt tree keeps the pairs kept for reuse (they name faces, not nodes).
      static_cast<void>(det.detect(g.p0, g.p1));
      det.rebuild(g.p1);
      const ProximityResult p = det.proximity(g.p1, reuse);
      const ProximityResult p_ref = ref.proximity(g.p1, reuse);
      EXPECT_GT(p.reused_pairs, 0u);
      EXPECT_EQ(p.vf, p_ref.vf);
      EXPECT_EQ(p.ee, p_ref.ee);
    }
  }
  EXPECT_GT(culled, 0u);  // the cones were in the loop
  EXPECT_GT(culled_pairs, 0u);
  EXPECT_GT(reused, 0u);
}

}  // namespace garment_test
}  // namespace clothcd
