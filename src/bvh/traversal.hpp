#pragma once
// Generic BVH traversals with template callables (no std::function or virtual call in the loop):
// self(N) = [skip if culled] self(L) + self(R) + pair(L, R), and pair(A, B) with box tests. Both
// run on a fixed stack whose overflow is checked in every build type, and in parallel over a
// frontier of tasks expanded serially from the root. step() is one task as the definition reads;
// run() makes the same tests in the same order with fewer stack moves.

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
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

// Out of line: keeps the push in the traversal loop small.
[[noreturn, gnu::noinline]] inline void stack_overflow() {
  throw std::length_error("BVH traversal stack overflow: more than " + std::to_string(kStackSize) +
                          " pending node pairs (a tree deeper than the builds make)");
}

/// Which node of an overlapping pair (x, y), not both leaves, a pair traversal splits: x (true)
/// when it is the larger, or y is a leaf. Every pair traversal splits by this rule, so that they
/// all walk the same node pairs.
[[nodiscard]] inline bool splits_first(const BvhNode& x, const BvhNode& y) {
  return y.is_leaf() || (!x.is_leaf() && x.count >= y.count);
}

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

  /// One task: hands the tasks it makes to `push`, the last one to run first (run_parallel's
  /// frontier, and the reference of run()).
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
    if (splits_first(x, y)) {
      push(Task{x.left + 1, t.b, false});
      push(Task{x.left, t.b, false});
    } else {
      push(Task{t.a, y.left + 1, false});
      push(Task{t.a, y.left, false});
    }
  }

  /// Runs `root` and everything below it: the tasks step() would make, in the same order, with
  /// the same box tests and culls, so the same leaf pairs in the same order. Leaner than step()
  /// in a loop: a pair task is tested before it is kept, so the stack holds only overlapping
  /// pairs; the walk continues into the first task a step makes instead of pushing and popping
  /// it; self tasks of leaves, which hold no pair, are never made.
  template <class Local>
  void run(const Task& root, TraversalCounters& c, Local& local) const {
    // Plain pointers and a local count: stores to `c` could alias the spans' sizes and force
    // their reload in the loop.
    const BvhNode* const xa = na.data();
    const BvhNode* const xb = nb.data();
    const std::uint8_t* const aa = active_a.empty() ? nullptr : active_a.data();
    const std::uint8_t* const ab = active_b.empty() ? nullptr : active_b.data();
    std::uint64_t box_tests = 0;
    // Whether the pair (a, b), nodes x and y, can hold a leaf pair: an active triangle on one
    // side (step()'s test: no box test without one) and overlapping boxes.
    auto admit = [&](int a, int b, const BvhNode& x, const BvhNode& y) {
      if (aa != nullptr && ab != nullptr && aa[a] == 0 && ab[b] == 0) return false;
      ++box_tests;
      return overlap(x, y);
    };
    std::array<Task, kStackSize> stack;
    int top = 0;
    auto push = [&](int a, int b, bool self) {
      if (top == kStackSize) stack_overflow();
      stack[top++] = Task{a, b, self};
    };
    Task t = root;
    // A root pair is tested like the pairs made below: a miss ends the run at once.
    if (!t.self && !admit(t.a, t.b, xa[t.a], xb[t.b])) {
      c.box_tests += box_tests;
      return;
    }
    for (;;) {
      if (t.self) {
        const BvhNode& n = xa[t.a];
        if (!n.is_leaf() && (aa == nullptr || aa[t.a] != 0)) {
          if (cull(t.a, c)) {
            ++c.culled;
          } else {
            const int l = n.left, r = n.left + 1;
            // step()'s order: self(l), then self(r), then the pair (l, r).
            if (admit(l, r, xa[l], xa[r])) push(l, r, false);
            if (!xa[r].is_leaf()) push(r, r, true);
            if (!xa[l].is_leaf()) {
              t = Task{l, l, true};
              continue;
            }
          }
        }
      } else {
        // An overlapping pair with an active side: split the larger node, test both children
        // against the other node (its box read once), go on with the first that overlaps.
        const BvhNode& x = xa[t.a];
        const BvhNode& y = xb[t.b];
        if (x.is_leaf() && y.is_leaf()) {
          leaf(t.a, t.b, local);
        } else if (splits_first(x, y)) {
          const int l = x.left;
          const bool hit0 = admit(l, t.b, xa[l], y);
          const bool hit1 = admit(l + 1, t.b, xa[l + 1], y);
          if (hit0) {
            if (hit1) push(l + 1, t.b, false);
            t.a = l;
            continue;
          }
          if (hit1) {
            t.a = l + 1;
            continue;
          }
        } else {
          const int l = y.left;
          const bool hit0 = admit(t.a, l, x, xb[l]);
          const bool hit1 = admit(t.a, l + 1, x, xb[l + 1]);
          if (hit0) {
            if (hit1) push(t.a, l + 1, false);
            t.b = l;
            continue;
          }
          if (hit1) {
            t.b = l + 1;
            continue;
          }
        }
      }
      if (top == 0) break;
      t = stack[--top];
    }
    c.box_tests += box_tests;
  }
};

template <class Cull, class Leaf>
Traversal<Cull, Leaf> make_traversal(std::span<const BvhNode> na, std::span<const BvhNode> nb,
                                     std::span<const std::uint8_t> active_a,
                                     std::span<const std::uint8_t> active_b, Cull cull, Leaf leaf) {
  return Traversal<Cull, Leaf>{na, nb, active_a, active_b, std::move(cull), std::move(leaf)};
}

/// Expands the root into a frontier of independent tasks, then runs them in parallel. Each thread
/// has its own `Local` (output buffer) and counters. With `rounds` > 1, the tasks run in that
/// many consecutive parallel rounds, and after_round() is called after each (the leaf pairs of
/// the frontier's expansion go with the first): a caller that consumes and empties the buffers
/// there holds one round's output at a time. The frontier has 512 tasks a round; the same box
/// tests, culls and leaf pairs whatever its width.
template <class Tr, class Local, class AfterRound>
TraversalCounters run_parallel(const Tr& tr, const Task& root,
                               tbb::enumerable_thread_specific<Local>& locals, std::size_t rounds,
                               AfterRound&& after_round) {
  TraversalCounters total;
  std::deque<Task> frontier{root};
  Local& serial = locals.local();
  // Wide enough for every round to keep the threads busy.
  const std::size_t width = std::size_t{512} * std::max<std::size_t>(1, rounds);
  // Breadth-first expansion until the frontier is wide enough (or the tree is exhausted).
  for (int guard = 0; !frontier.empty() && frontier.size() < width && guard < 100000; ++guard) {
    const Task t = frontier.front();
    frontier.pop_front();
    tr.step(t, total, serial, [&](const Task& s) { frontier.push_back(s); });
  }
  std::vector<Task> tasks(frontier.begin(), frontier.end());
  tbb::enumerable_thread_specific<TraversalCounters> counters;
  rounds = std::max<std::size_t>(1, std::min(rounds, tasks.size()));
  for (std::size_t k = 0; k < rounds; ++k) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(k * tasks.size() / rounds,
                                                      (k + 1) * tasks.size() / rounds, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        Local& local = locals.local();
                        TraversalCounters& c = counters.local();
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                          tr.run(tasks[i], c, local);
                      });
    after_round();
  }
  for (const auto& c : counters)
    total.add(c);
  return total;
}

template <class Tr, class Local>
TraversalCounters run_parallel(const Tr& tr, const Task& root,
                               tbb::enumerable_thread_specific<Local>& locals) {
  return run_parallel(tr, root, locals, 1, [] {});
}

}  // namespace clothcd::detail
