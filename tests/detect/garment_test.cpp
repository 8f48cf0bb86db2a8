// Sewn garments: the patch BVH keeps at least 99% of its
// internal nodes edge-connected; on a step from the drape to a smoothly perturbed pose the sound
// culling finds exactly what the unculled traversal finds in every policy and build, and on the
// dress it culls at least half as many triangle pairs as the paper's cone-only rule.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/procedural.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/sewing.hpp"
#include "support/data.hpp"

namespace clothcd {
namespace {

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
  const Positions moved = smooth_perturbation(vertices_matrix(garment), amplitude, 0.1, 1);
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
      o.verify = true;
      det.set_options(o);
      const DetectResult sound = det.detect(g.p0, g.p1);
      ASSERT_TRUE(sound.verified);
      EXPECT_TRUE(sound.missed_vf.empty());
      EXPECT_TRUE(sound.missed_ee.empty());
      EXPECT_EQ(sound.vf, none.vf);
      EXPECT_EQ(sound.ee, none.ee);
      o.culling = Culling::Cone;
      o.verify = false;
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
  o.verify = true;
  SelfDetector det(g.sewn.faces, g.sewn.num_vertices(), g.p0, o);
  const DetectResult r = det.detect(g.p0, g.p1);
  EXPECT_GE(r.stats.connected_share(), 0.99);
  ASSERT_TRUE(r.verified);
  EXPECT_GT(r.vf.size() + r.ee.size() + r.missed_vf.size() + r.missed_ee.size(), 0u);
  EXPECT_TRUE(r.missed_vf.empty());
  EXPECT_TRUE(r.missed_ee.empty());
}

}  // namespace
}  // namespace clothcd
