#pragma once
// The front of a pair traversal kept from one call to the next (DetectOptions::reuse_front): the
// node pairs at which the last traversal below each root pair stopped, so that the next one starts
// there instead of at the root pair.
//
// Why it finds the same leaf pairs: a parent's box is the union of its children's (refit takes
// their minima and maxima), so a leaf pair's boxes overlap only if every pair of their ancestors'
// boxes overlaps too. A traversal from any node pair (a, b) therefore reports exactly the
// overlapping leaf pairs of leaves(a) x leaves(b), and one from each pair of a set whose products
// partition leaves(a0) x leaves(b0) reports exactly what a traversal from (a0, b0) reports. The
// front is such a set for each root pair: it starts as the root pair itself, a traversal from an
// entry replaces it by the pairs where it stopped (misses, overlapping leaf pairs), and two
// missing entries (x, b), (y, b) with x, y the children of one node p become (p, b) when that
// pair misses too (likewise on the b side); both steps keep the partition. Only the order of the
// leaf pairs differs, and the number of box tests.

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "bvh/traversal.hpp"
#include "clothcd/bvh/bvh.hpp"

namespace clothcd::detail {

class TraversalFront {
 public:
  /// A root pair (a0, b0): the pair traversal of `root` (an id the caller's `live` understands).
  struct Root {
    int root, a0, b0;
  };

  /// `piece`: the most pairs of one root's front walked as one work item (a longer front is
  /// split, and two missing siblings on either side of a cut are not merged).
  explicit TraversalFront(std::uint32_t piece = 4096) : piece_(piece) {}

  [[nodiscard]] bool empty() const { return segments_ == 0; }
  /// Node pairs held.
  [[nodiscard]] std::size_t size() const { return size_; }
  /// Forgets the front and frees its memory (a rebuilt tree has other node ids).
  void clear() {
    arenas_[0].clear();
    arenas_[1].clear();
    segments_ = size_ = 0;
  }
  /// Starts a front at the root pairs themselves (the first run then traverses as a detector
  /// without a front does).
  void seed(std::span<const Root> roots) {
    clear();
    Arena& a = arenas_[cur_].local();
    for (const Root& r : roots) {
      a.segs.push_back({r, static_cast<std::uint32_t>(a.pairs.size()), 1, true});
      a.pairs.push_back({r.a0, r.b0});
    }
    segments_ = a.segs.size();
    size_ = a.pairs.size();
  }

  /// Traverses from the front of every root for which live(root) holds, the pairs of trees ta x tb
  /// (one tree twice for a self traversal), handing each overlapping leaf pair to leaf(x, y,
  /// local); the front of every other root goes back to its root pair (an old front would have
  /// to be merged back up from wherever the mesh was then). Returns the box tests made.
  template <class Live, class Leaf, class Local>
  std::uint64_t run(const Bvh& ta, const Bvh& tb, Live&& live, Leaf&& leaf,
                    tbb::enumerable_thread_specific<Local>& locals) {
    // Work items: each segment of the current front, long ones in pieces.
    struct Item {
      const Arena* arena;
      Segment seg;
    };
    std::vector<Item> items;
    for (const Arena& a : arenas_[cur_]) {
      for (const Segment& s : a.segs) {
        for (std::uint32_t k = 0; k < s.count; k += piece_) {
          Segment part = s;
          part.begin = s.begin + k;
          part.count = std::min<std::uint32_t>(piece_, s.count - k);
          part.head = s.head && k == 0;
          items.push_back({&a, part});
        }
      }
    }
    const int next = 1 - cur_;
    for (Arena& a : arenas_[next])
      a.clear();
    tbb::enumerable_thread_specific<std::uint64_t> tests(0);
    const Walk walk{ta, tb};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, items.size(), 16),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        Arena& out = arenas_[next].local();
                        Local& local = locals.local();
                        std::uint64_t& count = tests.local();
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          const Item& it = items[i];
                          const std::span<const NodePair> in(it.arena->pairs.data() + it.seg.begin,
                                                             it.seg.count);
                          Segment seg = it.seg;
                          seg.begin = static_cast<std::uint32_t>(out.pairs.size());
                          if (live(seg.root.root)) {
                            walk.run(in, out, count, [&](int x, int y) { leaf(x, y, local); });
                          } else if (seg.head) {
                            out.pairs.push_back({seg.root.a0, seg.root.b0});
                          }
                          seg.count = static_cast<std::uint32_t>(out.pairs.size()) - seg.begin;
                          if (seg.count > 0) out.segs.push_back(seg);
                        }
                      });
    cur_ = next;
    segments_ = size_ = 0;
    for (const Arena& a : arenas_[cur_]) {
      segments_ += a.segs.size();
      size_ += a.pairs.size();
    }
    std::uint64_t total = 0;
    for (std::uint64_t t : tests)
      total += t;
    return total;
  }

 private:
  struct NodePair {
    int a, b;
  };
  // A root's front, or a part of it, in DFS order: pairs[begin, begin + count) of its arena.
  // Exactly one segment of each root is its head.
  struct Segment {
    Root root;
    std::uint32_t begin = 0, count = 0;
    bool head = false;
  };
  // One thread's share of a front.
  struct Arena {
    std::vector<NodePair> pairs;
    std::vector<Segment> segs;
    std::vector<std::uint8_t> miss;  // Walk::run's scratch: whether pairs[i] missed this call
    void clear() {
      pairs.clear();
      segs.clear();
    }
  };
  static constexpr std::size_t kAhead = 8;

  // The traversal below a segment's pairs.
  struct Walk {
    const Bvh& ta;
    const Bvh& tb;

    // Appends the new front of `in` (pairs of one root's front) to out.pairs: each pair traversed
    // as Traversal::step does (splits_first), in DFS order, its stops appended, and adjacent
    // missing siblings merged.
    template <class Leaf>
    void run(std::span<const NodePair> in, Arena& out, std::uint64_t& tests, Leaf&& leaf) const {
      const BvhNode* const xa = ta.nodes().data();
      const BvhNode* const xb = tb.nodes().data();
      const std::size_t base = out.pairs.size();
      out.miss.resize(base);
      // A stop: kept, then merged with the stops before it while the pair above both misses. Only
      // a pair of the old front can merge: the pairs above a pair the walk reached overlapped.
      auto stop = [&](NodePair p, bool missed, bool merge) {
        while (merge && missed && out.pairs.size() > base && out.miss.back() != 0) {
          const NodePair q = out.pairs.back();  // before p in DFS order
          NodePair up;
          // Siblings q.a, p.a both lie below the root pair's a0 (every pair of a root's front
          // does), so their parent does too: a merge never leaves the root pair (likewise b).
          if (q.b == p.b && q.a != p.a && ta.parent(q.a) == ta.parent(p.a)) {
            up = {ta.parent(q.a), q.b};
          } else if (q.a == p.a && q.b != p.b && tb.parent(q.b) == tb.parent(p.b)) {
            up = {q.a, tb.parent(q.b)};
          } else {
            break;
          }
          ++tests;
          if (overlap(xa[up.a], xb[up.b])) break;
          out.pairs.pop_back();
          out.miss.pop_back();
          p = up;
        }
        out.pairs.push_back(p);
        out.miss.push_back(missed ? 1 : 0);
      };
      std::array<NodePair, kStackSize> stack;
      for (std::size_t i = 0; i < in.size(); ++i) {
        // The walk waits on the nodes of each pair (scattered over the tree): fetch them a few
        // pairs ahead.
        if (i + kAhead < in.size()) {
          __builtin_prefetch(&xa[in[i + kAhead].a]);
          __builtin_prefetch(&xb[in[i + kAhead].b]);
        }
        const NodePair& start = in[i];
        int top = 0;
        NodePair t = start;
        for (;;) {
          const BvhNode& x = xa[t.a];
          const BvhNode& y = xb[t.b];
          ++tests;
          if (!overlap(x, y)) {
            stop(t, true, top == 0 && t.a == start.a && t.b == start.b);
          } else if (x.is_leaf() && y.is_leaf()) {
            leaf(t.a, t.b);
            stop(t, false, false);
          } else {
            if (top == kStackSize) stack_overflow();
            if (splits_first(x, y)) {
              stack[top++] = {x.left + 1, t.b};
              t = {x.left, t.b};
            } else {
              stack[top++] = {t.a, y.left + 1};
              t = {t.a, y.left};
            }
            continue;
          }
          if (top == 0) break;
          t = stack[--top];
        }
      }
    }
  };

  tbb::enumerable_thread_specific<Arena> arenas_[2];
  std::uint32_t piece_;
  int cur_ = 0;
  std::size_t segments_ = 0, size_ = 0;
};

}  // namespace clothcd::detail
