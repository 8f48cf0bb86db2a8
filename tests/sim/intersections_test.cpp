// The intersection counter: the triangle test on hand-built cases, and the BVH-accelerated
// counts equal to testing every pair on crumpled random meshes. The repair of a starting shape's
// self crossings.
#include "clothcd/sim/intersections.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <random>

#include "clothcd/sim/simulation.hpp"
#include "grid.hpp"

namespace clothcd::sim {
namespace {

TEST(TrianglesIntersect, HandCases) {
  const Vec3 a0(0, 0, 0), a1(1, 0, 0), a2(0, 1, 0);
  // A triangle piercing a's interior.
  EXPECT_TRUE(triangles_intersect(a0, a1, a2, {0.2, 0.2, -1}, {0.3, 0.2, 1}, {0.2, 0.4, 1}));
  // The same lifted above the plane.
  EXPECT_FALSE(triangles_intersect(a0, a1, a2, {0.2, 0.2, 0.1}, {0.3, 0.2, 1}, {0.2, 0.4, 1}));
  // Crossing the plane outside the triangle.
  EXPECT_FALSE(triangles_intersect(a0, a1, a2, {2, 2, -1}, {3, 2, 1}, {2, 3, 1}));
  // Two triangles crossing edge through edge region (neither vertex inside the other).
  EXPECT_TRUE(
      triangles_intersect(a0, a1, a2, {0.25, -0.5, -0.5}, {0.25, -0.5, 0.5}, {0.25, 2.0, 0.0}));
  // Symmetric in argument order.
  EXPECT_TRUE(
      triangles_intersect({0.25, -0.5, -0.5}, {0.25, -0.5, 0.5}, {0.25, 2.0, 0.0}, a0, a1, a2));
  // Parallel planes.
  EXPECT_FALSE(triangles_intersect(a0, a1, a2, {0, 0, 1e-3}, {1, 0, 1e-3}, {0, 1, 1e-3}));
}

// A grid crumpled by random displacements has many crossings: the BVH and brute force agree.
TEST(IntersectionCounter, BvhEqualsBruteForceSelfAndBody) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 3; ++trial) {
    ClothMeshInput in = test::grid_cloth(12, 12, 0.1, 0.1);
    for (Vec3& p : in.positions)
      p += test::random_vec(rng, 0.012);
    const Topology cloth(in.faces, static_cast<int>(in.positions.size()));
    // A "body": another crumpled grid through the cloth.
    ClothMeshInput b = test::grid_cloth(8, 8, 0.1, 0.1, 0.0);
    for (Vec3& p : b.positions) {
      p = Vec3(p.x(), p.z() - 0.05, 0.05) + test::random_vec(rng, 0.01);
    }
    IntersectionCounter counter(cloth, {}, b.faces, static_cast<int>(b.positions.size()));
    const auto self_ref = counter.self_pairs_brute_force(in.positions);
    const auto body_ref = counter.body_pairs_brute_force(in.positions, b.positions);
    EXPECT_FALSE(self_ref.empty());
    EXPECT_FALSE(body_ref.empty());
    for (int threads : {1, 2}) {  // the traversals are parallel; the lists are merged and sorted
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      EXPECT_EQ(counter.self_pairs(in.positions), self_ref) << threads << " threads";
      EXPECT_EQ(counter.body_pairs(in.positions, b.positions), body_ref) << threads << " threads";
    }
  }
}

TEST(IntersectionCounter, FlatGridHasNoneAndStitchedPairsAreSkipped) {
  ClothMeshInput in = test::grid_cloth(6, 6, 0.1, 0.1);
  const int n = static_cast<int>(in.positions.size());
  const Topology cloth(in.faces, n);
  IntersectionCounter plain(cloth, {}, {}, 0);
  EXPECT_TRUE(plain.self_pairs(in.positions).empty());
  // Crumpled: crossings appear.
  std::mt19937_64 rng(3);
  std::vector<Vec3> x = in.positions;
  for (Vec3& p : x)
    p += test::random_vec(rng, 0.02);
  const auto crossings = plain.self_pairs(x);
  EXPECT_FALSE(crossings.empty());
  EXPECT_EQ(crossings, plain.self_pairs_brute_force(x));
  // A link between every two vertices hides them all.
  std::vector<std::pair<int, int>> ties;
  for (int v = 0; v < n; ++v) {
    for (int u = v + 1; u < n; ++u)
      ties.emplace_back(v, u);
  }
  IntersectionCounter tied(cloth, ties, {}, 0);
  EXPECT_TRUE(tied.self_pairs(x).empty());
}

// Two strips 1 mm apart sewn along their long edges by vertex-to-edge stitches (one chain from
// end to end): the seam links hold each stitch's vertices and the chain's vertices within one
// mean edge length, never the two ends of the seam.
TEST(SeamLinks, JoinNearbyVerticesOfAStitchChainOnly) {
  ClothMeshInput in = test::grid_cloth(10, 1, 0.1, 0.01);  // vertices 0-10 at z=0, 11-21 at z=1cm
  const ClothMeshInput other = test::grid_cloth(10, 1, 0.1, 0.01);
  const int n0 = static_cast<int>(in.positions.size());
  for (const Vec3& p : other.positions)
    in.positions.push_back(p + Vec3(0.0, 0.0, 0.011));  // 1 mm beyond the first strip's far edge
  for (const Face& f : other.faces)
    in.faces.push_back({f[0] + n0, f[1] + n0, f[2] + n0});
  // Vertex i of the first strip's far edge (11 + i) to the middle of edge (i, i+1) of the second
  // strip's near edge (n0 + i, n0 + i + 1).
  for (int i = 0; i < 10; ++i)
    in.stitches.push_back({11 + i, n0 + i, n0 + i + 1, 0.5});
  const ClothModel m(in, ClothMaterial{});
  const auto& links = m.seam_links();
  auto linked = [&](int a, int b) {
    return std::binary_search(links.begin(), links.end(),
                              std::pair(std::min(a, b), std::max(a, b)));
  };
  EXPECT_TRUE(std::is_sorted(links.begin(), links.end()));
  for (int i = 0; i < 10; ++i) {
    EXPECT_TRUE(linked(11 + i, n0 + i)) << i;      // a stitch term
    EXPECT_TRUE(linked(11 + i, n0 + i + 1)) << i;  // a stitch term
  }
  EXPECT_TRUE(linked(12, n0));        // same chain, 1.005 cm apart: within one mean edge (1.14 cm)
  EXPECT_FALSE(linked(11, n0 + 2));   // same chain, 2 cm apart
  EXPECT_FALSE(linked(11, n0 + 10));  // same chain, 10 cm apart
  EXPECT_FALSE(linked(0, n0));        // not on the seam
  // Counting: faces across the seam touch by construction and are not reported; a crossing far
  // from the seam still is.
  IntersectionCounter counter(m.topology(), links, {}, 0);
  EXPECT_TRUE(counter.self_pairs(m.initial_positions()).empty());
}

// Two 4 x 4 grids 2 mm apart (the upper one's vertices offset by 25), one vertex of the upper
// grid pushed 0.4 mm through the lower one: the faces around it cross the lower grid's faces.
ClothMeshInput pierced_sheets() {
  ClothMeshInput in = test::grid_cloth(4, 4, 0.04, 0.04);
  const ClothMeshInput up = test::grid_cloth(4, 4, 0.04, 0.04, 0.002);
  const int n = static_cast<int>(in.positions.size());
  for (const Vec3& p : up.positions)
    in.positions.push_back(p + Vec3(0.003, 0.0, 0.004));
  for (const Face& f : up.faces)
    in.faces.push_back({f[0] + n, f[1] + n, f[2] + n});
  in.positions[n + 12].y() = -0.0004;  // the upper grid's middle vertex (2, 2): vertex 37
  return in;
}

TEST(CrossingRepair, MovesThePiercingVertexBackThroughAndNothingElse) {
  ClothMeshInput in = pierced_sheets();
  const Topology cloth(in.faces, static_cast<int>(in.positions.size()));
  IntersectionCounter counter(cloth, {}, {}, 0);
  std::vector<Vec3> x = in.positions;
  // The fixture: every crossing pair is a lower face (0-31) and a face around vertex 37.
  const auto before = counter.self_pairs(x);
  ASSERT_FALSE(before.empty());
  for (const auto& [f, g] : before) {
    EXPECT_LT(f, 32) << f << " " << g;
    EXPECT_NE(std::find(in.faces[g].begin(), in.faces[g].end(), 37), in.faces[g].end()) << g;
  }
  const CrossingRepair r = repair_self_crossings(x, counter, cloth, {}, 1e-4);
  EXPECT_EQ(r.pairs_before, static_cast<long long>(before.size()));
  EXPECT_EQ(r.pairs_after, 0);
  EXPECT_TRUE(counter.self_pairs(x).empty());
  EXPECT_EQ(r.moves, 1);
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (i != 37) {
      EXPECT_EQ(x[i], in.positions[i]) << i;
    }
  }
  // Straight up through the lower plane to the margin above it: 0.5 mm.
  EXPECT_NEAR(x[37].y(), 1e-4, 1e-12);
  EXPECT_NEAR(r.largest_move, 5e-4, 1e-12);
}

TEST(CrossingRepair, APinnedPiercingVertexStaysAndTheOtherSheetGives) {
  ClothMeshInput in = pierced_sheets();
  const Topology cloth(in.faces, static_cast<int>(in.positions.size()));
  IntersectionCounter counter(cloth, {}, {}, 0);
  std::vector<Vec3> x = in.positions;
  std::vector<std::uint8_t> fixed(x.size(), 0);
  fixed[37] = 1;
  const CrossingRepair r = repair_self_crossings(x, counter, cloth, fixed, 1e-4);
  EXPECT_EQ(r.pairs_after, 0);
  EXPECT_TRUE(counter.self_pairs(x).empty());
  // One vertex of the lower sheet moved instead, nothing else.
  std::vector<int> moved;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i] != in.positions[i]) moved.push_back(static_cast<int>(i));
  }
  ASSERT_EQ(moved.size(), 1u);
  EXPECT_LT(moved[0], 25);
  EXPECT_EQ(r.moves, 1);
}

TEST(CrossingRepair, LeavesAShapeWithoutCrossingsBitwiseAlone) {
  const ClothMeshInput flat = test::grid_cloth(4, 4, 0.04, 0.04);
  const Topology flat_t(flat.faces, static_cast<int>(flat.positions.size()));
  IntersectionCounter flat_c(flat_t, {}, {}, 0);
  std::vector<Vec3> y = flat.positions;
  const CrossingRepair none = repair_self_crossings(y, flat_c, flat_t, {}, 1e-4);
  EXPECT_EQ(none.pairs_before, 0);
  EXPECT_EQ(none.moves, 0);
  EXPECT_EQ(y, flat.positions);
}

TEST(CrossingRepair, SimulationStartsFromTheRepairedShapeUnlessTheSceneSaysNo) {
  for (const bool repair : {true, false}) {
    Scene s;
    s.name = "pierced";
    s.cloth = pierced_sheets();
    s.collisions = true;
    s.repair_initial_crossings = repair;
    Simulation sim(std::move(s));
    const IntersectionCount c = sim.count_intersections();
    if (repair) {
      EXPECT_GT(sim.initial_repair().pairs_before, 0);
      EXPECT_EQ(sim.initial_repair().pairs_after, 0);
      EXPECT_EQ(c.self, 0);
    } else {
      EXPECT_EQ(sim.initial_repair().moves, 0);
      EXPECT_GT(c.self, 0);
    }
  }
}

}  // namespace
}  // namespace clothcd::sim
