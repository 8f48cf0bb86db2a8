// Per-node topology flags computed once at build: edge-connectedness (the gate of cone culling)
// and the disk test with its oriented boundary loop (the contour test, docs/algorithms.md 1.5).

#include <algorithm>

#include "clothcd/bvh/bvh.hpp"
#include "core/checked_index.hpp"

namespace clothcd {

std::span<const int> Bvh::contour(int node) const {
  const int b = contour_offsets_[node], e = contour_offsets_[node + 1];
  return {contour_vertices_.data() + b, static_cast<std::size_t>(e - b)};
}

int Bvh::num_internal() const {
  return static_cast<int>(
      std::count_if(nodes_.begin(), nodes_.end(), [](const BvhNode& n) { return !n.is_leaf(); }));
}
int Bvh::num_connected_internal() const {
  return static_cast<int>(std::count_if(nodes_.begin(), nodes_.end(), [](const BvhNode& n) {
    return !n.is_leaf() && n.connected();
  }));
}
int Bvh::num_disk_internal() const {
  return static_cast<int>(std::count_if(nodes_.begin(), nodes_.end(),
                                        [](const BvhNode& n) { return !n.is_leaf() && n.disk(); }));
}

std::vector<std::uint8_t> Bvh::nodes_holding(std::span<const std::uint8_t> face_flags) const {
  std::vector<std::uint8_t> out(nodes_.size(), 0);
  // Children come after their parent, so a backward sweep sees both before the parent.
  for (int i = static_cast<int>(nodes_.size()) - 1; i >= 0; --i) {
    const BvhNode& n = nodes_[i];
    out[i] = n.is_leaf() ? face_flags[prim_ids_[n.first]] : (out[n.left] | out[n.left + 1]);
  }
  return out;
}

void Bvh::compute_flags(const Topology& topo) {
  const int nn = static_cast<int>(nodes_.size());
  std::vector<int> pos(topo.num_faces());
  for (int i = 0; i < static_cast<int>(prim_ids_.size()); ++i)
    pos[prim_ids_[i]] = i;

  // Connectedness: both children connected and some edge joins them is enough; otherwise (a
  // spatial split may cut a connected set into disconnected halves) search the node's face graph.
  std::vector<int> seen(topo.num_faces(), -1), queue;
  auto in_node = [&](const BvhNode& n, int g) {
    return pos[g] >= n.first && pos[g] < n.first + n.count;
  };
  for (int i = nn - 1; i >= 0; --i) {
    BvhNode& n = nodes_[i];
    if (n.is_leaf()) {
      n.flags = BvhNode::kConnected | BvhNode::kDisk;
      continue;
    }
    const BvhNode& l = nodes_[n.left];
    const BvhNode& r = nodes_[n.left + 1];
    n.flags = 0;
    bool connected = false;
    if (l.connected() && r.connected()) {
      const BvhNode& small = l.count <= r.count ? l : r;
      const BvhNode& large = l.count <= r.count ? r : l;
      for (int p = small.first; p < small.first + small.count && !connected; ++p) {
        for (int e : topo.face_edges(prim_ids_[p])) {
          for (int g : topo.edge_faces(e))
            connected = connected || in_node(large, g);
        }
      }
    } else {
      queue.assign(1, prim_ids_[n.first]);
      seen[queue[0]] = i;
      for (std::size_t k = 0; k < queue.size(); ++k) {
        for (int e : topo.face_edges(queue[k])) {
          for (int g : topo.edge_faces(e)) {
            if (seen[g] != i && in_node(n, g)) {
              seen[g] = i;
              queue.push_back(g);
            }
          }
        }
      }
      connected = static_cast<int>(queue.size()) == n.count;
    }
    if (connected) n.flags = BvhNode::kConnected;
  }

  // Disk test of connected internal nodes with stamped scratch arrays (no hashing).
  std::vector<int> vstamp(topo.num_vertices(), -1), outstamp(topo.num_vertices(), -1);
  std::vector<int> next(topo.num_vertices(), -1);
  std::vector<int> estamp(topo.num_edges(), -1), ecount(topo.num_edges(), 0);
  std::vector<int> efrom(topo.num_edges(), -1);
  contour_offsets_.assign(nn + 1, 0);
  contour_vertices_.clear();
  std::vector<int> loop;
  for (int i = 0; i < nn; ++i) {
    // The loops of all disk nodes together can outgrow the int offsets long before the face ids
    // do (a node's loop is counted at every level above its faces).
    contour_offsets_[i] = detail::checked_int(contour_vertices_.size(), "BVH contours");
    BvhNode& n = nodes_[i];
    if (n.is_leaf() || !n.connected()) continue;
    const int s = i;
    int nv = 0, ne = 0;
    bool ok = true;
    for (int p = n.first; p < n.first + n.count && ok; ++p) {
      const int f = prim_ids_[p];
      const Face& t = topo.faces()[f];
      for (int k = 0; k < 3; ++k) {
        const int a = t[k];
        if (vstamp[a] != s) {
          vstamp[a] = s;
          ++nv;
        }
        const int e = topo.face_edges(f)[k];
        if (estamp[e] != s) {
          estamp[e] = s;
          ecount[e] = 1;
          efrom[e] = a;
          ++ne;
        } else {
          ++ecount[e];
          // Manifold and consistently oriented: an inner edge is used twice, in opposite senses.
          if (ecount[e] > 2 || efrom[e] == a) ok = false;
        }
      }
    }
    if (!ok || nv - ne + n.count != 1) continue;
    int nb = 0, start = -1;
    for (int p = n.first; p < n.first + n.count && ok; ++p) {
      const int f = prim_ids_[p];
      const Face& t = topo.faces()[f];
      for (int k = 0; k < 3; ++k) {
        const int e = topo.face_edges(f)[k];
        if (ecount[e] != 1) continue;
        const int a = t[k], b = t[(k + 1) % 3];
        if (outstamp[a] == s) ok = false;  // a boundary vertex touched twice: a pinch
        outstamp[a] = s;
        next[a] = b;
        if (start < 0) start = a;
        ++nb;
      }
    }
    if (!ok || nb < 3) continue;
    loop.clear();
    int v = start;
    do {
      loop.push_back(v);
      if (outstamp[v] != s || static_cast<int>(loop.size()) > nb) {
        ok = false;
        break;
      }
      v = next[v];
    } while (v != start);
    if (!ok || static_cast<int>(loop.size()) != nb) continue;
    n.flags |= BvhNode::kDisk;
    contour_vertices_.insert(contour_vertices_.end(), loop.begin(), loop.end());
  }
  contour_offsets_[nn] = detail::checked_int(contour_vertices_.size(), "BVH contours");
}

}  // namespace clothcd
