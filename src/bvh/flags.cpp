// Per-node topology flags computed once at build: edge-connectedness (the gate of cone culling)
// and the disk test with its oriented boundary loop (the contour test, docs/algorithms.md 1.5).

#include <algorithm>
#include <numeric>

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

  // Connectedness from the edge adjacencies: faces f and g sharing an edge part at one node, the
  // lowest holding both, where their leaf positions fall on different sides. Counting the
  // components bottom-up (a node has its children's, less the merges its own adjacencies make in
  // a union-find over the faces) gives every node's at once. Nodes are numbered after their
  // ancestors, so a backward sweep has merged a node's descendants, and only those among its
  // faces, when it reaches the node.
  struct Join {
    int node, f, g;
  };
  std::vector<Join> joins;
  joins.reserve(topo.num_edges());
  for (int e = 0; e < topo.num_edges(); ++e) {
    const auto ef = topo.edge_faces(e);
    for (std::size_t x = 0; x < ef.size(); ++x) {
      for (std::size_t y = x + 1; y < ef.size(); ++y) {
        const int p = pos[ef[x]], q = pos[ef[y]];
        int i = 0;
        for (;;) {
          const BvhNode& l = nodes_[nodes_[i].left];
          const bool pl = p < l.first + l.count, ql = q < l.first + l.count;
          if (pl != ql) break;
          i = pl ? nodes_[i].left : nodes_[i].left + 1;
        }
        joins.push_back({i, ef[x], ef[y]});
      }
    }
  }
  std::sort(joins.begin(), joins.end(),
            [](const Join& x, const Join& y) { return x.node > y.node; });
  std::size_t next_join = 0;
  std::vector<int> parent(topo.num_faces()), comps(nn, 0);
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int f) {
    while (parent[f] != f) {
      parent[f] = parent[parent[f]];
      f = parent[f];
    }
    return f;
  };
  for (int i = nn - 1; i >= 0; --i) {
    BvhNode& n = nodes_[i];
    if (n.is_leaf()) {
      n.flags = BvhNode::kConnected | BvhNode::kDisk;
      comps[i] = 1;
      continue;
    }
    comps[i] = comps[n.left] + comps[n.left + 1];
    for (; next_join < joins.size() && joins[next_join].node == i; ++next_join) {
      const int a = root(joins[next_join].f), b = root(joins[next_join].g);
      if (a == b) continue;
      parent[a] = b;
      --comps[i];
    }
    n.flags = comps[i] == 1 ? BvhNode::kConnected : 0;
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
