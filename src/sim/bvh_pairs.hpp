#pragma once
// Overlapping leaf pairs of clothcd BVHs (static or swept boxes, refit by the caller), for the
// simulator's proximity queries against the body and its intersection counts.

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/bvh/bvh.hpp"

namespace clothcd::sim::detail {

/// One step of a two-tree descent from node pair (i, j): nothing when a_mask excludes i or the
/// boxes miss, leaf(face_a, face_b) for two leaves, else push(child pair) twice, splitting the
/// larger node.
template <class Leaf, class Push>
void descend(const Bvh& a, int i, const Bvh& b, int j, std::span<const std::uint8_t> a_mask,
             Leaf&& leaf, Push&& push) {
  if (!a_mask.empty() && !a_mask[i]) return;
  const BvhNode& x = a.nodes()[i];
  const BvhNode& y = b.nodes()[j];
  if (!overlap(x, y)) return;
  if (x.is_leaf() && y.is_leaf()) {
    leaf(a.prim_ids()[x.first], b.prim_ids()[y.first]);
  } else if (y.is_leaf() || (!x.is_leaf() && x.count >= y.count)) {
    push(x.left, j);
    push(x.left + 1, j);
  } else {
    push(i, y.left);
    push(i, y.left + 1);
  }
}

/// Calls fn(face_a, face_b) for every pair of a leaf below node `i` of `a` and a leaf below node
/// `j` of `b` whose boxes overlap; with `a_mask` (one flag per node of `a`), only below nodes of
/// `a` whose flag is set.
template <class Fn>
void for_each_overlap_below(const Bvh& a, int i0, const Bvh& b, int j0, Fn&& fn,
                            std::span<const std::uint8_t> a_mask = {}) {
  std::vector<std::pair<int, int>> stack{{i0, j0}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    descend(a, i, b, j, a_mask, fn, [&](int p, int q) { stack.emplace_back(p, q); });
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

/// Like for_each_overlap, in parallel: fn(face_a, face_b, local) with the calling thread's
/// `Local` from `locals`. The calls come in no fixed order: callers merge and sort.
template <class Local, class Fn>
void for_each_overlap_parallel(const Bvh& a, const Bvh& b,
                               tbb::enumerable_thread_specific<Local>& locals, Fn&& fn,
                               std::span<const std::uint8_t> a_mask = {}) {
  if (a.nodes().empty() || b.nodes().empty()) return;
  // Breadth-first to a frontier of node pairs, then each pair's subtrees as one task.
  constexpr std::size_t kTasks = 256;
  std::vector<std::pair<int, int>> frontier{{0, 0}}, next;
  Local& serial = locals.local();
  while (!frontier.empty() && frontier.size() < kTasks) {
    next.clear();
    for (const auto& [i, j] : frontier) {
      descend(
          a, i, b, j, a_mask, [&](int f, int g) { fn(f, g, serial); },
          [&](int p, int q) { next.emplace_back(p, q); });
    }
    frontier.swap(next);
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, frontier.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      Local& local = locals.local();
                      for (std::size_t k = r.begin(); k != r.end(); ++k) {
                        for_each_overlap_below(
                            a, frontier[k].first, b, frontier[k].second,
                            [&](int f, int g) { fn(f, g, local); }, a_mask);
                      }
                    });
}

/// Calls fn(f, g, local) once for every unordered pair of distinct leaves of `a` whose boxes
/// overlap: for every internal node, the pairs across its two children, each node one task, with
/// the calling thread's `Local` from `locals`. The calls come in no fixed order: callers merge
/// and sort.
template <class Local, class Fn>
void for_each_self_overlap_parallel(const Bvh& a, tbb::enumerable_thread_specific<Local>& locals,
                                    Fn&& fn) {
  const auto& n = a.nodes();
  std::vector<int> internal;
  for (int k = 0; k < static_cast<int>(n.size()); ++k) {
    if (!n[k].is_leaf()) internal.push_back(k);
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, internal.size(), 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      Local& local = locals.local();
                      for (std::size_t k = r.begin(); k != r.end(); ++k) {
                        const BvhNode& x = n[internal[k]];
                        for_each_overlap_below(a, x.left, a, x.left + 1,
                                               [&](int f, int g) { fn(f, g, local); });
                      }
                    });
}

}  // namespace clothcd::sim::detail
