#pragma once
// Overlapping leaf pairs of clothcd BVHs (static or swept boxes, refit by the caller), for the
// simulator's proximity queries against the body and its intersection counts.

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/bvh/bvh.hpp"

namespace clothcd::sim::detail {

/// Calls fn(face_a, face_b) for every pair of a leaf below node `i` of `a` and a leaf below node
/// `j` of `b` whose boxes overlap; with `a_mask` (one flag per node of `a`), only below nodes of
/// `a` whose flag is set.
template <class Fn>
void for_each_overlap_below(const Bvh& a, int i0, const Bvh& b, int j0, Fn&& fn,
                            std::span<const std::uint8_t> a_mask = {}) {
  const auto& na = a.nodes();
  const auto& nb = b.nodes();
  std::vector<std::pair<int, int>> stack{{i0, j0}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    const BvhNode& x = na[i];
    const BvhNode& y = nb[j];
    if (!a_mask.empty() && !a_mask[i]) continue;
    if (!overlap(x, y)) continue;
    if (x.is_leaf() && y.is_leaf()) {
      fn(a.prim_ids()[x.first], b.prim_ids()[y.first]);
    } else if (y.is_leaf() || (!x.is_leaf() && x.count >= y.count)) {
      stack.emplace_back(x.left, j);
      stack.emplace_back(x.left + 1, j);
    } else {
      stack.emplace_back(i, y.left);
      stack.emplace_back(i, y.left + 1);
    }
  }
}

/// Calls fn(face_a, face_b) for every pair of leaves of `a` and `b` whose boxes overlap (below
/// flagged nodes of `a` only, when `a_mask` is given).
template <class Fn>
void for_each_overlap(const Bvh& a, const Bvh& b, Fn&& fn,
                      std::span<const std::uint8_t> a_mask = {}) {
  if (a.nodes().empty() || b.nodes().empty()) return;
  for_each_overlap_below(a, 0, b, 0, fn, a_mask);
}

/// Calls fn(f, g) once for every unordered pair of distinct leaves of `a` whose boxes overlap:
/// for every internal node, the pairs across its two children.
template <class Fn>
void for_each_self_overlap(const Bvh& a, Fn&& fn) {
  const auto& n = a.nodes();
  if (n.empty()) return;
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const BvhNode& x = n[stack.back()];
    stack.pop_back();
    if (x.is_leaf()) continue;
    stack.push_back(x.left);
    stack.push_back(x.left + 1);
    for_each_overlap_below(a, x.left, a, x.left + 1, fn);
  }
}

}  // namespace clothcd::sim::detail
