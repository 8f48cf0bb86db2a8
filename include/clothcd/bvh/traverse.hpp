#pragma once
/// @file
/// The broad phase on its own: box-overlap traversals of refit BVHs that hand every pair of
/// overlapping leaves to your callable, as face ids. Refit the trees first (Bvh::refit): the
/// traversals read the boxes of the last refit and never cull by normal cones (the detectors do
/// that on top of the same traversal).
///
/// What is reported:
/// - every pair of leaves whose closed boxes overlap, each unordered pair once; in a self
///   traversal never a face with itself;
/// - pairs of faces sharing a vertex or an edge included (their boxes always overlap): drop them
///   where your narrow phase does not want them (the candidates stage, clothcd/detect/
///   candidates.hpp, does);
/// - in no particular order: neither the pairs nor the two faces of a self pair are sorted.

#include <functional>
#include <utility>
#include <vector>

#include "clothcd/bvh/bvh.hpp"

namespace clothcd {

/// Receives the two face ids of one pair of overlapping leaves.
using LeafPairFn = std::function<void(int face_a, int face_b)>;

/// Every pair of distinct faces of `bvh` whose leaf boxes overlap. Serial: on_leaf_pair is called
/// on the calling thread, one call at a time, so it may keep state without locks. An exception it
/// throws ends the traversal and propagates. Throws std::length_error for a tree deeper than the
/// builds make (the traversal's stack is fixed).
void self_traverse(const Bvh& bvh, const LeafPairFn& on_leaf_pair);

/// Every pair (face_a of `a`, face_b of `b`) whose leaf boxes overlap: two trees, e.g. of two
/// meshes, or of one mesh and a static body. Serial, like self_traverse.
void pair_traverse(const Bvh& a, const Bvh& b, const LeafPairFn& on_leaf_pair);

/// The pairs self_traverse reports, found in parallel: each thread collects into its own list
/// and the lists are concatenated (no callable, so nothing to make thread-safe).
[[nodiscard]] std::vector<std::pair<int, int>> overlapping_leaf_pairs(const Bvh& bvh);

/// The pairs pair_traverse reports (face of `a`, face of `b`), found in parallel.
[[nodiscard]] std::vector<std::pair<int, int>> overlapping_leaf_pairs(const Bvh& a, const Bvh& b);

}  // namespace clothcd
