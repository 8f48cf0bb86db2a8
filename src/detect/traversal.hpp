#pragma once
// Generic BVH traversals with template callables (no std::function or virtual call in the loop):
// self(N) = [skip if culled] self(L) + self(R) + pair(L, R), and pair(A, B) with box tests. Both
// run on a fixed stack whose overflow is checked in every build type, and in parallel over a
// frontier of tasks expanded serially from the root.

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <array>
#include <deque>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "clothcd/bvh/bvh.hpp"

namespace clothcd::detail {

/// A self task when a == b (same tree), else a pair task (a of the first tree, b of the second).
struct Task {
  int a, b;
  bool self;
};

struct TraversalCounters {
  std::uint64_t box_tests = 0, culled = 0, cone_tests = 0, contour_tests = 0, contour_fails = 0;
  void add(const TraversalCounters& o) {
    box_tests += o.box_tests;
    culled += o.culled;
    cone_tests += o.cone_tests;
    contour_tests += o.contour_tests;
    contour_fails += o.contour_fails;
  }
};

/// Pending tasks of one run. A self task leaves at most 2 tasks behind as it descends a level and
/// a pair task 1, so a tree of depth D never needs more than 4 D + 1: the builds stay below 130
/// levels (patch splits stop at depth 96, median splits halve), so 1024 leaves room. A deeper tree
/// makes run() throw (every build type), never write past the stack.
inline constexpr int kStackSize = 1024;

/// Runs one task: `cull(node, counters)` decides self skips, `leaf(a, b)` receives overlapping
/// leaf pairs, `active_a/b` (optional, per node) prune subtrees without active triangles.
template <class Cull, class Leaf>
struct Traversal {
  std::span<const BvhNode> na, nb;  // nb == na for self traversal
  std::span<const std::uint8_t> active_a, active_b;
  Cull cull;
  Leaf leaf;

  [[nodiscard]] bool act_a(int i) const { return active_a.empty() || active_a[i] != 0; }
  [[nodiscard]] bool act_b(int i) const { return active_b.empty() || active_b[i] != 0; }

  template <class Push, class Local>
  void step(const Task& t, TraversalCounters& c, Local& local, Push&& push) const {
    if (t.self) {
      const BvhNode& n = na[t.a];
      if (n.is_leaf() || !act_a(t.a)) return;
      if (cull(t.a, c)) {
        ++c.culled;
        return;
      }
      push(Task{n.left, n.left + 1, false});
      push(Task{n.left + 1, n.left + 1, true});
      push(Task{n.left, n.left, true});
      return;
    }
    // A pair task needs an active triangle on at least one side (both trees share active_a in a
    // self traversal, where the pair's sides are the same tree).
    if (!act_a(t.a) && !act_b(t.b)) return;
    const BvhNode& x = na[t.a];
    const BvhNode& y = nb[t.b];
    ++c.box_tests;
    if (!overlap(x, y)) return;
    if (x.is_leaf() && y.is_leaf()) {
      leaf(t.a, t.b, local);
      return;
    }
    const bool split_a = y.is_leaf() || (!x.is_leaf() && x.count >= y.count);
    if (split_a) {
      push(Task{x.left + 1, t.b, false});
      push(Task{x.left, t.b, false});
    } else {
      push(Task{t.a, y.left + 1, false});
      push(Task{t.a, y.left, false});
    }
  }

  template <class Local>
  void run(const Task& root, TraversalCounters& c, Local& local) const {
    std::array<Task, kStackSize> stack;
    int top = 0;
    stack[top++] = root;
    while (top > 0) {
      const Task t = stack[--top];
      step(t, c, local, [&](const Task& s) {
        if (top == kStackSize) {
          throw std::length_error("BVH traversal stack overflow: more than " +
                                  std::to_string(kStackSize) +
                                  " pending node pairs (a tree deeper than the builds make)");
        }
        stack[top++] = s;
      });
    }
  }
};

template <class Cull, class Leaf>
Traversal<Cull, Leaf> make_traversal(std::span<const BvhNode> na, std::span<const BvhNode> nb,
                                     std::span<const std::uint8_t> active_a,
                                     std::span<const std::uint8_t> active_b, Cull cull, Leaf leaf) {
  return Traversal<Cull, Leaf>{na, nb, active_a, active_b, std::move(cull), std::move(leaf)};
}

/// Expands the root into a frontier of independent tasks, then runs them in parallel. Each thread
/// has its own `Local` (output buffer) and counters.
template <class Tr, class Local>
TraversalCounters run_parallel(const Tr& tr, const Task& root,
                               tbb::enumerable_thread_specific<Local>& locals) {
  TraversalCounters total;
  std::deque<Task> frontier{root};
  Local& serial = locals.local();
  constexpr std::size_t kFrontier = 512;
  // Breadth-first expansion until the frontier is wide enough (or the tree is exhausted).
  for (int guard = 0; !frontier.empty() && frontier.size() < kFrontier && guard < 100000; ++guard) {
    const Task t = frontier.front();
    frontier.pop_front();
    tr.step(t, total, serial, [&](const Task& s) { frontier.push_back(s); });
  }
  std::vector<Task> tasks(frontier.begin(), frontier.end());
  tbb::enumerable_thread_specific<TraversalCounters> counters;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tasks.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      Local& local = locals.local();
                      TraversalCounters& c = counters.local();
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        tr.run(tasks[i], c, local);
                    });
  for (const auto& c : counters)
    total.add(c);
  return total;
}

}  // namespace clothcd::detail
