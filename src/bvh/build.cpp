// BVH construction: spatial median splits or edge-connected patch splits, then a breadth-first
// relayout so each depth is one contiguous range of nodes.

#include <algorithm>
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
      : topo_(topo), build_(build) {
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
  }

  std::vector<TmpNode> run() {
    nodes_.reserve(2 * perm_.size());
    if (!perm_.empty()) split(0, static_cast<int>(perm_.size()), 0);
    return std::move(nodes_);
  }
  std::vector<int>& perm() { return perm_; }

 private:
  int split(int first, int count, int depth) {
    const int id = static_cast<int>(nodes_.size());
    nodes_.push_back({first, count, -1, -1});
    if (count == 1) return id;
    int mid = 0;
    if (build_ == BvhBuild::Patch && depth < kMaxPatchDepth) {
      mid = patch_split(first, count);
    } else {
      mid = median_split(first, count);
    }
    const int l = split(first, mid, depth + 1);
    const int r = split(first + mid, count - mid, depth + 1);
    nodes_[id].left = l;
    nodes_[id].right = r;
    return id;
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

  template <class Fn>
  void for_each_neighbour(int f, Fn&& fn) const {
    for (int e : topo_.face_edges(f)) {
      for (int g : topo_.edge_faces(e)) {
        if (g != f && in_set_[g] == stamp_) fn(g);
      }
    }
  }

  // Edge-connected components of the faces in the current set (marked in_set_ == stamp_).
  std::vector<std::vector<int>> components(std::span<const int> faces) {
    std::vector<std::vector<int>> comps;
    ++seen_stamp_;
    for (int s : faces) {
      if (seen_[s] == seen_stamp_) continue;
      comps.emplace_back();
      auto& c = comps.back();
      seen_[s] = seen_stamp_;
      c.push_back(s);
      for (std::size_t k = 0; k < c.size(); ++k) {
        for_each_neighbour(c[k], [&](int g) {
          if (seen_[g] != seen_stamp_) {
            seen_[g] = seen_stamp_;
            c.push_back(g);
          }
        });
      }
    }
    return comps;
  }

  // Splits [first, first + count) into two parts written back in place; returns the size of the
  // first. Disconnected sets are split between whole components (grouped along the longest axis);
  // a connected set is split into two connected halves grown from one end of its longest axis.
  int patch_split(int first, int count) {
    ++stamp_;
    std::span<int> faces(perm_.data() + first, count);
    for (int f : faces)
      in_set_[f] = stamp_;
    auto comps = components(faces);
    std::vector<int> a, b;
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
      grow_halves(faces, a, b);
      if (a.empty() || b.empty()) return median_split(first, count);
    }
    std::copy(a.begin(), a.end(), faces.begin());
    std::copy(b.begin(), b.end(), faces.begin() + static_cast<std::ptrdiff_t>(a.size()));
    return static_cast<int>(a.size());
  }

  void grow_halves(std::span<int> faces, std::vector<int>& a, std::vector<int>& b) {
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
    in_a_[seed] = stamp_;
    while (!heap.empty() && static_cast<int>(a.size()) < count / 2) {
      const int f = heap.top().second;
      heap.pop();
      a.push_back(f);
      for_each_neighbour(f, [&](int g) {
        if (in_a_[g] != stamp_) {
          in_a_[g] = stamp_;
          heap.emplace(centroid_[g][axis], g);
        }
      });
    }
    // in_a_ also marks the queued front; rebuild it from `a` alone.
    ++stamp_;
    for (int f : faces)
      in_set_[f] = stamp_;
    for (int f : a)
      in_a_[f] = stamp_;
    std::vector<int> rest;
    for (int f : faces) {
      if (in_a_[f] != stamp_) rest.push_back(f);
    }
    // Keep the largest component of the rest as the second half; the others touch the first half
    // (the set is connected), so moving them there keeps both halves connected.
    for (int f : a)
      in_set_[f] = -1;
    auto comps = components(rest);
    std::size_t best = 0;
    for (std::size_t c = 1; c < comps.size(); ++c) {
      if (comps[c].size() > comps[best].size()) best = c;
    }
    for (std::size_t c = 0; c < comps.size(); ++c) {
      if (c == best) continue;
      a.insert(a.end(), comps[c].begin(), comps[c].end());
    }
    if (!comps.empty()) b = comps[best];
    // Deterministic order inside each half does not matter for correctness; sort for stability.
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
  }

  const Topology& topo_;
  BvhBuild build_;
  std::vector<Eigen::Vector3d> centroid_;
  std::vector<int> perm_;
  std::vector<TmpNode> nodes_;
  std::vector<int> in_set_, in_a_, seen_;
  int stamp_ = 0, seen_stamp_ = 0;
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
  cones_.resize(nodes_.size());
  faces_ = topology.faces();
  prim_faces_.resize(prim_ids_.size());
  for (std::size_t i = 0; i < prim_ids_.size(); ++i)
    prim_faces_[i] = faces_[prim_ids_[i]];
  num_vertices_ = topology.num_vertices();
}

}  // namespace clothcd
