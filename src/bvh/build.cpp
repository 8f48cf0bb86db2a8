// BVH construction: spatial median splits or edge-connected patch splits, then a breadth-first
// relayout so each depth is one contiguous range of nodes.

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <numeric>
#include <queue>
#include <stdexcept>
#include <utility>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/core/error.hpp"

#include <fmt/format.h>
#include <limits>

namespace clothcd {
namespace {

// Deep trees only come from pathological patch splits; past this depth we split by count.
constexpr int kMaxPatchDepth = 96;

struct TmpNode {
  int first = 0, count = 0;
  int left = -1, right = -1;
};

class Builder {
 public:
  Builder(const Topology& topo, std::span<const Eigen::Vector3d> ref, BvhBuild build)
      : build_(build) {
    const int nf = topo.num_faces();
    centroid_.resize(nf);
    for (int f = 0; f < nf; ++f) {
      const auto& t = topo.faces()[f];
      centroid_[f] = (ref[t[0]] + ref[t[1]] + ref[t[2]]) / 3.0;
    }
    perm_.resize(nf);
    std::iota(perm_.begin(), perm_.end(), 0);
    in_set_.assign(nf, -1);
    in_a_.assign(nf, -1);
    seen_.assign(nf, -1);
    if (build == BvhBuild::Patch) {
      // Each face's edge neighbours side by side: the patch splits walk them at every level.
      neighbour_offsets_.assign(nf + 1, 0);
      for (int f = 0; f < nf; ++f) {
        for (int e : topo.face_edges(f))
          neighbour_offsets_[f + 1] += static_cast<int>(topo.edge_faces(e).size()) - 1;
      }
      std::partial_sum(neighbour_offsets_.begin(), neighbour_offsets_.end(),
                       neighbour_offsets_.begin());
      neighbours_.resize(neighbour_offsets_[nf]);
      for (int f = 0, k = 0; f < nf; ++f) {
        for (int e : topo.face_edges(f)) {
          for (int g : topo.edge_faces(e)) {
            if (g != f) neighbours_[k++] = g;
          }
        }
      }
    }
  }

  // The nodes in depth-first order (a node, its left subtree, its right subtree). A subtree over
  // c faces has 2 c - 1 nodes, so each node's index follows from the sizes alone: the two
  // subtrees of a split are built in parallel and the tree is the same whatever the threads.
  std::vector<TmpNode> run() {
    const int n = static_cast<int>(perm_.size());
    nodes_.assign(n > 0 ? 2 * static_cast<std::size_t>(n) - 1 : 0, TmpNode{});
    if (n > 0) split(0, n, 0, 0);
    return std::move(nodes_);
  }
  std::vector<int>& perm() { return perm_; }

 private:
  // Subtrees over fewer faces are built by the thread that split their parent.
  static constexpr int kParallelFaces = 2048;

  void split(int first, int count, int depth, int id) {
    nodes_[id] = {first, count, -1, -1};
    if (count == 1) return;
    int mid = 0;
    if (build_ == BvhBuild::Patch && depth < kMaxPatchDepth) {
      mid = patch_split(first, count);
    } else {
      mid = median_split(first, count);
    }
    const int l = id + 1, r = id + 2 * mid;
    nodes_[id].left = l;
    nodes_[id].right = r;
    const auto left = [&] { split(first, mid, depth + 1, l); };
    const auto right = [&] { split(first + mid, count - mid, depth + 1, r); };
    if (count >= kParallelFaces) {
      tbb::parallel_invoke(left, right);
    } else {
      left();
      right();
    }
  }

  // A stamp no other call has used (concurrent splits mark their own faces with their own).
  int new_stamp() { return next_stamp_.fetch_add(1, std::memory_order_relaxed); }

  // Whether face g is marked with `stamp` as in the current set. Relaxed atomic: a concurrent
  // split may be marking g, which is then in its set and never carries this stamp.
  bool in_set(int g, int stamp) {
    return std::atomic_ref<int>(in_set_[g]).load(std::memory_order_relaxed) == stamp;
  }
  void mark_set(int g, int stamp) {
    std::atomic_ref<int>(in_set_[g]).store(stamp, std::memory_order_relaxed);
  }

  int longest_axis(int first, int count) const {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (int i = first; i < first + count; ++i) {
      lo = lo.cwiseMin(centroid_[perm_[i]]);
      hi = hi.cwiseMax(centroid_[perm_[i]]);
    }
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    return axis;
  }

  // Object median along the longest axis of the centroids; ties broken by face id so the build is
  // deterministic.
  int median_split(int first, int count) {
    const int axis = longest_axis(first, count);
    const int mid = count / 2;
    auto b = perm_.begin() + first;
    std::nth_element(b, b + mid, b + count, [&](int x, int y) {
      const double cx = centroid_[x][axis], cy = centroid_[y][axis];
      return cx < cy || (cx == cy && x < y);
    });
    return mid;
  }

  // fn(g) for the faces g sharing an edge with f in the set marked `stamp`, in the order of f's
  // edges and of each edge's faces (a face sharing two edges with f comes twice).
  template <class Fn>
  void for_each_neighbour(int f, int stamp, Fn&& fn) {
    for (int k = neighbour_offsets_[f]; k < neighbour_offsets_[f + 1]; ++k) {
      const int g = neighbours_[k];
      if (in_set(g, stamp)) fn(g);
    }
  }

  // Edge-connected components of a face set, one after another in `faces` (each in the order its
  // breadth-first search reached it): component c is faces[start[c], start[c + 1]). Two
  // allocations whatever the number of components.
  struct Components {
    std::vector<int> faces, start;
    [[nodiscard]] std::size_t size() const { return start.size() - 1; }
    [[nodiscard]] std::span<const int> operator[](std::size_t c) const {
      return {faces.data() + start[c], static_cast<std::size_t>(start[c + 1] - start[c])};
    }
  };

  // Edge-connected components of `faces`, the set marked `stamp`.
  Components components(std::span<const int> faces, int stamp) {
    Components comps;
    comps.faces.reserve(faces.size());
    comps.start.push_back(0);
    std::vector<int>& out = comps.faces;
    const int seen = new_stamp();
    for (int s : faces) {
      if (seen_[s] == seen) continue;
      seen_[s] = seen;
      out.push_back(s);
      for (std::size_t k = comps.start.back(); k < out.size(); ++k) {
        for_each_neighbour(out[k], stamp, [&](int g) {
          if (seen_[g] != seen) {
            seen_[g] = seen;
            out.push_back(g);
          }
        });
      }
      comps.start.push_back(static_cast<int>(out.size()));
    }
    return comps;
  }

  // Splits [first, first + count) into two parts written back in place; returns the size of the
  // first. Disconnected sets are split between whole components (grouped along the longest axis);
  // a connected set is split into two connected halves grown from one end of its longest axis.
  int patch_split(int first, int count) {
    const int stamp = new_stamp();
    std::span<int> faces(perm_.data() + first, count);
    for (int f : faces)
      mark_set(f, stamp);
    auto comps = components(faces, stamp);
    std::vector<int> a, b;
    a.reserve(count);
    b.reserve(count);
    if (comps.size() > 1) {
      const int axis = longest_axis(first, count);
      std::vector<std::pair<double, int>> order;
      for (int c = 0; c < static_cast<int>(comps.size()); ++c) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int f : comps[c])
          sum += centroid_[f];
        order.emplace_back(sum[axis] / comps[c].size(), c);
      }
      std::sort(order.begin(), order.end());
      int acc = 0;
      std::size_t k = 0;
      // At least one component on each side; stop once half the faces are on the first side.
      for (; k + 1 < order.size(); ++k) {
        const int sz = static_cast<int>(comps[order[k].second].size());
        if (k > 0 && acc + sz / 2 > count / 2) break;
        acc += sz;
        for (int f : comps[order[k].second])
          a.push_back(f);
      }
      for (; k < order.size(); ++k) {
        for (int f : comps[order[k].second])
          b.push_back(f);
      }
    } else {
      grow_halves(faces, stamp, a, b);
      if (a.empty() || b.empty()) return median_split(first, count);
    }
    std::copy(a.begin(), a.end(), faces.begin());
    std::copy(b.begin(), b.end(), faces.begin() + static_cast<std::ptrdiff_t>(a.size()));
    return static_cast<int>(a.size());
  }

  // `faces`: a connected set, marked `stamp`.
  void grow_halves(std::span<int> faces, int stamp, std::vector<int>& a, std::vector<int>& b) {
    const int count = static_cast<int>(faces.size());
    const int first = static_cast<int>(faces.data() - perm_.data());
    const int axis = longest_axis(first, count);
    int seed = faces[0];
    for (int f : faces) {
      const double cf = centroid_[f][axis], cs = centroid_[seed][axis];
      if (cf < cs || (cf == cs && f < seed)) seed = f;
    }
    // Grow the first half in order of the coordinate along the axis (a front sweeping the patch).
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
    heap.emplace(centroid_[seed][axis], seed);
    in_a_[seed] = stamp;
    while (!heap.empty() && static_cast<int>(a.size()) < count / 2) {
      const int f = heap.top().second;
      heap.pop();
      a.push_back(f);
      for_each_neighbour(f, stamp, [&](int g) {
        if (in_a_[g] != stamp) {
          in_a_[g] = stamp;
          heap.emplace(centroid_[g][axis], g);
        }
      });
    }
    // in_a_ also marks the queued front; rebuild it from `a` alone.
    const int rest_stamp = new_stamp();
    for (int f : faces)
      mark_set(f, rest_stamp);
    for (int f : a)
      in_a_[f] = rest_stamp;
    std::vector<int> rest;
    for (int f : faces) {
      if (in_a_[f] != rest_stamp) rest.push_back(f);
    }
    // Keep the largest component of the rest as the second half; the others touch the first half
    // (the set is connected), so moving them there keeps both halves connected.
    for (int f : a)
      mark_set(f, -1);
    auto comps = components(rest, rest_stamp);
    std::size_t best = 0;
    for (std::size_t c = 1; c < comps.size(); ++c) {
      if (comps[c].size() > comps[best].size()) best = c;
    }
    for (std::size_t c = 0; c < comps.size(); ++c) {
      if (c == best) continue;
      a.insert(a.end(), comps[c].begin(), comps[c].end());
    }
    if (comps.size() > 0) b.assign(comps[best].begin(), comps[best].end());
    // Deterministic order inside each half does not matter for correctness; sort for stability.
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
  }

  BvhBuild build_;
  std::vector<Eigen::Vector3d> centroid_;
  std::vector<int> perm_;
  std::vector<TmpNode> nodes_;
  // Per-face marks: a split's faces (in_set_), its first half (in_a_), a component search's
  // visits (seen_). Each mark is a stamp from new_stamp(); concurrent splits own disjoint faces.
  std::vector<int> in_set_, in_a_, seen_;
  std::vector<int> neighbour_offsets_, neighbours_;  // CSR, Patch builds only
  std::atomic<int> next_stamp_{0};
};

}  // namespace

Bvh::Bvh(const Topology& topology, std::span<const Eigen::Vector3d> reference, BvhBuild build) {
  build_tree(topology, reference, build);
  compute_flags(topology);
}

Bvh Bvh::boxes_only(const Topology& topology, std::span<const Eigen::Vector3d> reference,
                    BvhBuild build) {
  Bvh b;
  b.build_tree(topology, reference, build);
  b.contour_offsets_.assign(b.nodes_.size() + 1, 0);  // no node has a contour
  return b;
}

void Bvh::build_tree(const Topology& topology, std::span<const Eigen::Vector3d> reference,
                     BvhBuild build) {
  if (static_cast<int>(reference.size()) != topology.num_vertices()) {
    throw InputError(fmt::format("BVH reference shape has {} vertices, the topology {}",
                                 reference.size(), topology.num_vertices()));
  }
  Builder builder(topology, reference, build);
  std::vector<TmpNode> tmp = builder.run();
  prim_ids_ = std::move(builder.perm());

  // Breadth-first relayout: children adjacent and after their parent, depths contiguous.
  nodes_.reserve(tmp.size());
  level_offsets_.clear();
  std::vector<int> current;
  if (!tmp.empty()) current.push_back(0);
  while (!current.empty()) {
    level_offsets_.push_back(static_cast<int>(nodes_.size()));
    const int next_start = static_cast<int>(nodes_.size() + current.size());
    std::vector<int> next;
    for (int t : current) {
      BvhNode n;
      n.first = tmp[t].first;
      n.count = tmp[t].count;
      if (tmp[t].left >= 0) {
        n.left = next_start + static_cast<int>(next.size());
        next.push_back(tmp[t].left);
        next.push_back(tmp[t].right);
      }
      nodes_.push_back(n);
    }
    current = std::move(next);
  }
  level_offsets_.push_back(static_cast<int>(nodes_.size()));
  leaf_of_face_.assign(topology.num_faces(), -1);
  parent_.assign(nodes_.size(), -1);
  for (int i = 0; i < static_cast<int>(nodes_.size()); ++i) {
    if (nodes_[i].is_leaf()) {
      leaf_of_face_[prim_ids_[nodes_[i].first]] = i;
    } else {
      parent_[nodes_[i].left] = parent_[nodes_[i].left + 1] = i;
    }
  }
  cones_.clear();  // sized by the first refit with cones
  faces_ = topology.shared_faces();
  prim_faces_.resize(prim_ids_.size());
  for (std::size_t i = 0; i < prim_ids_.size(); ++i)
    prim_faces_[i] = (*faces_)[prim_ids_[i]];
  num_vertices_ = topology.num_vertices();
}

}  // namespace clothcd
