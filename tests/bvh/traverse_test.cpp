// The public traversals against brute force: the pairs reported are exactly the face pairs whose
// refit leaf boxes overlap, each once, in the serial and the parallel forms.

#include "clothcd/bvh/traverse.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "bvh/traversal.hpp"
#include "clothcd/research/procedural.hpp"

// Helpers in a namespace of their own: the tests of a folder may share one translation unit.
namespace clothcd::traverse_test {
namespace {

std::vector<Eigen::Vector3d> points(const Positions& p, const Eigen::Vector3d& shift = {0, 0, 0}) {
  std::vector<Eigen::Vector3d> v(p.rows());
  for (int i = 0; i < p.rows(); ++i)
    v[i] = p.row(i).transpose() + shift;
  return v;
}

using PairSet = std::set<std::pair<int, int>>;

// Unordered self pairs as (smaller, larger); fails on a repeat or a face paired with itself.
PairSet self_set(const std::vector<std::pair<int, int>>& pairs) {
  PairSet s;
  for (auto [f, g] : pairs) {
    EXPECT_NE(f, g);
    EXPECT_TRUE(s.emplace(std::min(f, g), std::max(f, g)).second) << f << " " << g;
  }
  return s;
}

PairSet brute_force(const Bvh& a, const Bvh& b, bool self) {
  PairSet s;
  const int na = static_cast<int>(a.faces().size()), nb = static_cast<int>(b.faces().size());
  for (int f = 0; f < na; ++f) {
    for (int g = self ? f + 1 : 0; g < nb; ++g) {
      if (overlap(a.nodes()[a.leaf_of_face(f)], b.nodes()[b.leaf_of_face(g)])) s.emplace(f, g);
    }
  }
  return s;
}

TEST(Traverse, SelfPairsAreTheOverlappingLeafBoxes) {
  for (const auto& s : {research::crumpled_sheet(14, 3), research::twisted_strip(40, 3),
                        research::winding_strip(48, 2)}) {
    const Topology topo(s.faces, s.num_vertices);
    const auto v0 = points(s.v_t0), v1 = points(s.v_t1);
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      for (double thickness : {0.0, 0.02}) {
        SCOPED_TRACE(::testing::Message()
                     << s.name << " build " << int(build) << " thickness " << thickness);
        Bvh bvh(topo, v0, build);
        RefitOptions ro;
        ro.thickness = thickness;
        bvh.refit(v0, v1, ro);
        const PairSet expected = brute_force(bvh, bvh, true);
        std::vector<std::pair<int, int>> serial;
        self_traverse(bvh, [&](int f, int g) { serial.emplace_back(f, g); });
        EXPECT_EQ(self_set(serial), expected);
        EXPECT_EQ(self_set(overlapping_leaf_pairs(bvh)), expected);
        // Vertex-sharing pairs are reported: every edge-adjacent pair, for one.
        int adjacent = 0;
        for (auto [f, g] : expected)
          adjacent += topo.faces_share_vertex(f, g) ? 1 : 0;
        EXPECT_GT(adjacent, topo.num_faces());
      }
    }
  }
}

TEST(Traverse, PairPairsAreTheOverlappingLeafBoxesOfTwoMeshes) {
  // Two crumpled sheets, the second shifted so that they overlap in part.
  const research::ProceduralScene a = research::crumpled_sheet(7, 1),
                                  b = research::crumpled_sheet(5, 2);
  const Topology ta(a.faces, a.num_vertices), tb(b.faces, b.num_vertices);
  const Eigen::Vector3d shift(0.3, 0.05, 0.2);
  const auto a0 = points(a.v_t0), a1 = points(a.v_t1);
  const auto b0 = points(b.v_t0, shift), b1 = points(b.v_t1, shift);
  Bvh ba(ta, a0, BvhBuild::Spatial);
  Bvh bb = Bvh::boxes_only(tb, b0, BvhBuild::Patch);
  RefitOptions ro;
  ro.cones = false;
  ba.refit(a0, a1, ro);
  bb.refit(b0, b1, ro);
  for (bool swap : {false, true}) {
    const Bvh& x = swap ? bb : ba;
    const Bvh& y = swap ? ba : bb;
    const PairSet expected = brute_force(x, y, false);
    ASSERT_FALSE(expected.empty());
    ASSERT_LT(expected.size(), x.faces().size() * y.faces().size());
    std::vector<std::pair<int, int>> serial;
    pair_traverse(x, y, [&](int f, int g) { serial.emplace_back(f, g); });
    const PairSet got(serial.begin(), serial.end());
    EXPECT_EQ(got.size(), serial.size());  // each once
    EXPECT_EQ(got, expected);
    const auto parallel = overlapping_leaf_pairs(x, y);
    EXPECT_EQ(PairSet(parallel.begin(), parallel.end()), expected);
    EXPECT_EQ(parallel.size(), expected.size());
  }
}

// What the traversal runs, leaf pairs (node ids, in order) and counters, against the plain loop
// of its single steps that run() streamlines.
struct Trace {
  std::vector<std::pair<int, int>> leaves;
  detail::TraversalCounters c;
};

template <class Tr>
Trace by_steps(const Tr& tr, const detail::Task& root) {
  Trace t;
  std::vector<detail::Task> stack{root};
  while (!stack.empty()) {
    const detail::Task task = stack.back();
    stack.pop_back();
    tr.step(task, t.c, t.leaves, [&](const detail::Task& s) { stack.push_back(s); });
  }
  return t;
}

template <class Tr>
Trace by_run(const Tr& tr, const detail::Task& root) {
  Trace t;
  tr.run(root, t.c, t.leaves);
  return t;
}

void expect_same(const Trace& a, const Trace& b) {
  EXPECT_EQ(a.leaves, b.leaves);
  EXPECT_EQ(a.c.box_tests, b.c.box_tests);
  EXPECT_EQ(a.c.culled, b.c.culled);
  EXPECT_EQ(a.c.cone_tests, b.c.cone_tests);
}

TEST(Traverse, RunMakesTheSameTestsAndPairsAsItsSteps) {
  const research::ProceduralScene a = research::crumpled_sheet(12, 4),
                                  b = research::twisted_strip(40, 3);
  const Topology ta(a.faces, a.num_vertices), tb(b.faces, b.num_vertices);
  const auto a0 = points(a.v_t0), a1 = points(a.v_t1);
  const auto b0 = points(b.v_t0, {0.2, 0.1, 0.0}), b1 = points(b.v_t1, {0.2, 0.1, 0.0});
  std::mt19937_64 rng(11);
  for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
    Bvh x(ta, a0, build), y(tb, b0, build);
    RefitOptions ro;
    ro.thickness = 0.01;
    x.refit(a0, a1, ro);
    y.refit(b0, b1, ro);
    // Culls a fixed third of the internal nodes, counting every question as a cone test.
    auto cull = [](int i, detail::TraversalCounters& c) {
      ++c.cone_tests;
      return i % 3 == 1;
    };
    auto no_cull = [](int, detail::TraversalCounters&) { return false; };
    auto leaf = [](int i, int j, std::vector<std::pair<int, int>>& out) { out.emplace_back(i, j); };
    // The nodes above a random eighth of the faces, as the detectors' active restriction.
    auto random_flags = [&](const Bvh& t) {
      std::vector<std::uint8_t> f(t.faces().size());
      for (auto& v : f)
        v = rng() % 8 == 0 ? 1 : 0;
      return t.nodes_holding(f);
    };
    const std::vector<std::uint8_t> fx = random_flags(x), fy = random_flags(y);
    const std::span<const BvhNode> nx = x.nodes(), ny = y.nodes();
    for (bool active : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "build " << int(build) << " active " << active);
      std::span<const std::uint8_t> ax, ay;
      if (active) {
        ax = fx;
        ay = fy;
      }
      const auto self = detail::make_traversal(nx, nx, ax, ax, cull, leaf);
      const auto plain = detail::make_traversal(nx, nx, ax, ax, no_cull, leaf);
      const auto two = detail::make_traversal(nx, ny, ax, ay, no_cull, leaf);
      const auto swapped = detail::make_traversal(ny, nx, ay, ax, no_cull, leaf);
      const Trace s = by_steps(self, {0, 0, true}), p = by_steps(plain, {0, 0, true});
      const Trace t = by_steps(two, {0, 0, false}), w = by_steps(swapped, {0, 0, false});
      ASSERT_GT(s.c.culled, 0u);
      ASSERT_GT(p.leaves.size(), s.leaves.size());
      ASSERT_FALSE(t.leaves.empty());
      expect_same(by_run(self, {0, 0, true}), s);
      expect_same(by_run(plain, {0, 0, true}), p);
      expect_same(by_run(two, {0, 0, false}), t);
      expect_same(by_run(swapped, {0, 0, false}), w);
      // Roots below the top, as the parallel frontier hands them out.
      for (int i : {1, 2, 5}) {
        expect_same(by_run(self, {i, i, true}), by_steps(self, {i, i, true}));
        expect_same(by_run(plain, {1, i, false}), by_steps(plain, {1, i, false}));
        expect_same(by_run(two, {i, 2, false}), by_steps(two, {i, 2, false}));
      }
    }
  }
}

TEST(Traverse, TinyAndEmptyTrees) {
  const Topology one(std::vector<Face>{{0, 1, 2}}, 3);
  const std::vector<Eigen::Vector3d> v{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  Bvh b(one, v, BvhBuild::Spatial);
  b.refit(v, RefitOptions{});
  int calls = 0;
  self_traverse(b, [&](int, int) { ++calls; });
  EXPECT_EQ(calls, 0);
  pair_traverse(b, b, [&](int f, int g) {
    EXPECT_EQ(f, 0);
    EXPECT_EQ(g, 0);
    ++calls;
  });
  EXPECT_EQ(calls, 1);
  const Bvh empty;
  self_traverse(empty, [&](int, int) { ++calls; });
  pair_traverse(empty, b, [&](int, int) { ++calls; });
  EXPECT_EQ(calls, 1);
  EXPECT_TRUE(overlapping_leaf_pairs(empty).empty());
  EXPECT_TRUE(overlapping_leaf_pairs(b, empty).empty());
}

}  // namespace
}  // namespace clothcd::traverse_test
