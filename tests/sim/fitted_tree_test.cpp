// The simulator's self-rebuilding BVH: built at its first refit, refit in place while the mesh
// deforms a little, built afresh (the same tree as a build on the new shape) once its boxes have
// loosened; and the intersection counter, which uses it, equal to brute force across a rebuild.
#include "sim/fitted_tree.hpp"

#include <gtest/gtest.h>

#include <random>

#include "clothcd/sim/intersections.hpp"
#include "grid.hpp"

namespace clothcd::sim {
namespace {

// The grid folded in half across x (the second half 2 mm above the first): faces of both halves
// share nodes of a tree built folded; unfolded, those nodes span the sheet.
std::vector<Vec3> folded(const ClothMeshInput& in) {
  std::vector<Vec3> x = in.positions;
  for (Vec3& p : x) {
    if (p.x() > 0.5) p = Vec3(1.0 - p.x(), 2e-3, p.z());
  }
  return x;
}

void expect_same_nodes(const Bvh& a, const Bvh& b) {
  ASSERT_EQ(a.nodes().size(), b.nodes().size());
  EXPECT_EQ(a.prim_ids(), b.prim_ids());
  for (std::size_t i = 0; i < a.nodes().size(); ++i) {
    EXPECT_EQ(a.nodes()[i].lo, b.nodes()[i].lo) << i;
    EXPECT_EQ(a.nodes()[i].hi, b.nodes()[i].hi) << i;
    EXPECT_EQ(a.nodes()[i].left, b.nodes()[i].left) << i;
  }
}

TEST(FittedTree, RefitsInPlaceUntilItsBoxesLoosenThenRebuildsOnTheNewShape) {
  const ClothMeshInput in = test::grid_cloth(16, 16, 1.0, 1.0);
  const Topology topo(in.faces, static_cast<int>(in.positions.size()));
  const std::vector<Vec3> start = folded(in);
  RefitOptions ro;
  ro.cones = false;
  ro.thickness = 1e-3;
  detail::FittedTree tree(topo);
  EXPECT_EQ(tree.builds(), 0);
  tree.refit(start, ro);
  EXPECT_EQ(tree.builds(), 1);

  // A small motion: the same tree, refit.
  std::mt19937_64 rng(3);
  std::vector<Vec3> moved = start;
  for (Vec3& p : moved)
    p += test::random_vec(rng, 1e-4);
  tree.refit(moved, ro);
  EXPECT_EQ(tree.builds(), 1);
  Bvh kept = Bvh::boxes_only(topo, start, BvhBuild::Spatial);
  kept.refit(moved, ro);
  expect_same_nodes(tree.bvh(), kept);

  // Unfolded: rebuilt, the tree a build on the unfolded sheet gives.
  tree.refit(in.positions, ro);
  EXPECT_EQ(tree.builds(), 2);
  Bvh fresh = Bvh::boxes_only(topo, in.positions, BvhBuild::Spatial);
  fresh.refit(in.positions, ro);
  expect_same_nodes(tree.bvh(), fresh);
  // And kept while the sheet stays flat.
  tree.refit(in.positions, ro);
  EXPECT_EQ(tree.builds(), 2);
}

// Counts on the folded sheet build the counter's trees; the same counter on the sheet unfolded
// and then crumpled (many crossings), through the rebuilds, finds exactly the brute-force pairs.
TEST(FittedTree, IntersectionCountsEqualBruteForceAcrossRebuilds) {
  const ClothMeshInput in = test::grid_cloth(14, 14, 1.0, 1.0);
  const Topology cloth(in.faces, static_cast<int>(in.positions.size()));
  const ClothMeshInput b = test::grid_cloth(6, 6, 1.0, 1.0, 0.0);
  std::vector<Vec3> body = b.positions;
  IntersectionCounter counter(cloth, {}, b.faces, static_cast<int>(body.size()));
  EXPECT_TRUE(counter.self_pairs(folded(in)).empty());
  std::mt19937_64 rng(11);
  for (int round = 0; round < 3; ++round) {
    std::vector<Vec3> x = in.positions;
    for (Vec3& p : x)
      p += test::random_vec(rng, 0.1 * (round + 1));
    for (Vec3& p : body)
      p = Vec3(p.x(), 0.3 * p.z() - 0.15, p.z()) + test::random_vec(rng, 0.05);
    const auto self_ref = counter.self_pairs_brute_force(x);
    const auto body_ref = counter.body_pairs_brute_force(x, body);
    EXPECT_FALSE(self_ref.empty());
    EXPECT_FALSE(body_ref.empty());
    EXPECT_EQ(counter.self_pairs(x), self_ref) << "round " << round;
    EXPECT_EQ(counter.body_pairs(x, body), body_ref) << "round " << round;
  }
}

}  // namespace
}  // namespace clothcd::sim
