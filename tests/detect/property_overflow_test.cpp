// The overflow checks that let the detector hold for millions of triangles or fail clearly,
// without a mesh that large: the traversal's fixed stack on deliberately deep trees (a chain of
// nodes, which no build makes), the depth the builds actually reach, and the 32-bit index check.

#include <gtest/gtest.h>

#include <climits>
#include <stdexcept>
#include <string>

#include "bvh/traversal.hpp"
#include "core/checked_index.hpp"
#include "property_scenes.hpp"

namespace clothcd {
namespace {

using namespace clothcd::test;

// A chain `depth` levels deep: every internal node's first child is the next internal node and
// its second a leaf; the last internal node has two leaves. All boxes overlap, so the self
// traversal must report every pair of the depth + 1 leaves.
std::vector<BvhNode> chain(int depth) {
  // Breadth-first, children adjacent: level d >= 1 is (internal node, leaf) at 2d - 1 and 2d;
  // the last level is two leaves.
  std::vector<BvhNode> nodes(2 * static_cast<std::size_t>(depth) + 1);
  int leaves = 0;
  for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
    BvhNode& n = nodes[i];
    n.hi = {1, 1, 1};
    const int level = (i + 1) / 2;
    const bool internal = level < depth && (i == 0 || i % 2 == 1);
    if (internal) {
      n.left = 2 * level + 1;
    } else {
      n.first = leaves++;
      n.count = 1;
    }
  }
  for (int i = static_cast<int>(nodes.size()) - 1; i >= 0; --i) {
    if (!nodes[i].is_leaf())
      nodes[i].count = nodes[nodes[i].left].count + nodes[nodes[i].left + 1].count;
  }
  return nodes;
}

std::uint64_t self_pairs(const std::vector<BvhNode>& nodes) {
  std::uint64_t pairs = 0;
  auto tr = detail::make_traversal(
      std::span<const BvhNode>(nodes), std::span<const BvhNode>(nodes), {}, {},
      [](int, detail::TraversalCounters&) { return false; },
      [](int, int, std::uint64_t& out) { ++out; });
  detail::TraversalCounters c;
  tr.run({0, 0, true}, c, pairs);
  return pairs;
}

TEST(DetectOverflow, ChainTreeWellInsideTheStackFindsEveryPair) {
  for (int depth : {1, 2, 10, 300}) {
    const std::vector<BvhNode> nodes = chain(depth);
    ASSERT_EQ(nodes[0].count, depth + 1);
    const std::uint64_t n = static_cast<std::uint64_t>(depth) + 1;
    EXPECT_EQ(self_pairs(nodes), n * (n - 1) / 2) << "depth " << depth;
  }
}

TEST(DetectOverflow, ChainTreeDeeperThanTheStackThrowsAClearError) {
  const std::vector<BvhNode> nodes = chain(2 * detail::kStackSize);
  try {
    (void)self_pairs(nodes);
    ADD_FAILURE() << "no error";
  } catch (const std::length_error& e) {
    EXPECT_NE(std::string(e.what()).find("stack overflow"), std::string::npos) << e.what();
  }
}

// What keeps the fixed stack sound: the trees the builds make on degenerate random scenes and
// on a long strip stay within the depth the stack allows (4 depth + 1 pending tasks at most).
TEST(DetectOverflow, BuiltTreesStayWithinTheTraversalStack) {
  auto check = [](const std::vector<Face>& faces, const Positions& v) {
    const Topology topo(faces, static_cast<int>(v.rows()));
    std::vector<Eigen::Vector3d> pts(v.rows());
    for (Eigen::Index i = 0; i < v.rows(); ++i)
      pts[i] = v.row(i).transpose();
    for (BvhBuild b : {BvhBuild::Spatial, BvhBuild::Patch}) {
      const Bvh bvh(topo, pts, b);
      EXPECT_LE(4 * bvh.depth() + 1, detail::kStackSize) << "build " << int(b);
      EXPECT_LE(bvh.depth(), 130) << "build " << int(b);
    }
  };
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const RandomScene s = random_scene(seed, 2);
    check(s.faces, s.v0);
  }
  // A strip 1 x 5000 quads, and the same strip folded in a zigzag so that its far parts lie close.
  std::vector<Face> faces;
  const int len = 5000;
  Positions v(2 * (len + 1), 3);
  for (int i = 0; i <= len; ++i) {
    const double x = (i % 200 < 100 ? i % 100 : 99 - i % 100) * 0.01, z = (i / 100) * 0.001;
    v.row(2 * i) << x, 0, z;
    v.row(2 * i + 1) << x, 0.01, z;
    if (i < len) {
      faces.push_back({2 * i, 2 * i + 2, 2 * i + 3});
      faces.push_back({2 * i, 2 * i + 3, 2 * i + 1});
    }
  }
  check(faces, v);
}

TEST(DetectOverflow, SizesPastIntMaxAreAnErrorNamingWhatOverflowed) {
  EXPECT_EQ(detail::checked_int(0, "x"), 0);
  EXPECT_EQ(detail::checked_int(static_cast<std::size_t>(INT_MAX), "x"), INT_MAX);
  try {
    (void)detail::checked_int(static_cast<std::size_t>(INT_MAX) + 1, "BVH contours");
    ADD_FAILURE() << "no error";
  } catch (const std::length_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("BVH contours"), std::string::npos) << msg;
    EXPECT_NE(msg.find("2147483648"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace clothcd
