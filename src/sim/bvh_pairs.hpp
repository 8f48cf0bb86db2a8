#pragma once
// Overlapping leaf pairs of clothcd BVHs (static or swept boxes, refit by the caller), for the
// simulator's proximity queries against the body and its intersection counts.

#include <utility>
#include <vector>

#include "clothcd/bvh/bvh.hpp"

namespace clothcd::sim::detail {

/// Calls fn(face_a, face_b) for every pair of leaves of `a` and `b` whose boxes overlap.
template <class Fn>
void for_each_overlap(const Bvh& a, const Bvh& b, Fn&& fn) {
  const auto& na = a.nodes();
  const auto& nb = b.nodes();
  if (na.empty() || nb.empty()) return;
  std::vector<std::pair<int, int>> stack{{0, 0}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    const BvhNode& x = na[i];
    const BvhNode& y = nb[j];
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

/// Calls fn(f, g) once for every unordered pair of distinct leaves of `a` whose boxes overlap.
template <class Fn>
void for_each_self_overlap(const Bvh& a, Fn&& fn) {
  const auto& n = a.nodes();
  if (n.empty()) return;
  // (i, i) entries mean "pairs inside node i"; (i, j) with i != j mean "pairs across i and j".
  std::vector<std::pair<int, int>> stack{{0, 0}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    const BvhNode& x = n[i];
    if (i == j) {
      if (x.is_leaf()) continue;
      stack.emplace_back(x.left, x.left);
      stack.emplace_back(x.left + 1, x.left + 1);
      stack.emplace_back(x.left, x.left + 1);
      continue;
    }
    const BvhNode& y = n[j];
    if (!overlap(x, y)) continue;
    if (x.is_leaf() && y.is_leaf()) {
      fn(a.prim_ids()[x.first], a.prim_ids()[y.first]);
    } else if (y.is_leaf() || (!x.is_leaf() && x.count >= y.count)) {
      stack.emplace_back(x.left, j);
      stack.emplace_back(x.left + 1, j);
    } else {
      stack.emplace_back(i, y.left);
      stack.emplace_back(i, y.left + 1);
    }
  }
}

}  // namespace clothcd::sim::detail
