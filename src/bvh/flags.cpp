// Per-node topology flags computed once at build: edge-connectedness (the gate of cone culling)
// and the disk test with its oriented boundary loop (the contour test, docs/algorithms.md 1.5).

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>
#include <span>

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
  // From each flagged face's leaf upwards, until a node already holds its bits: that node's
  // ancestors hold them too (every node written holds the OR of what was written below it).
  const std::size_t n = std::min(face_flags.size(), leaf_of_face_.size());
  for (std::size_t f = 0; f < n; ++f) {
    const std::uint8_t bits = face_flags[f];
    if (bits == 0) continue;
    for (int i = leaf_of_face_[f]; i >= 0 && (out[i] & bits) != bits; i = parent_[i])
      out[i] |= bits;
  }
  return out;
}

namespace {

// Stamped scratch arrays of the disk test (no hashing): vertex and edge entries stamped with the
// node being tested, and the boundary loops found so far.
struct DiskScratch {
  std::vector<int> vstamp, outstamp, next, estamp, ecount, efrom, loops;
  explicit DiskScratch(const Topology& topo)
      : vstamp(topo.num_vertices(), -1),
        outstamp(topo.num_vertices(), -1),
        next(topo.num_vertices(), -1),
        estamp(topo.num_edges(), -1),
        ecount(topo.num_edges(), 0),
        efrom(topo.num_edges(), -1) {}
};

// Whether the faces of node s (`faces`) form a disk: manifold, consistently oriented, Euler
// characteristic 1, one boundary loop without pinches. Appends that loop to sc.loops when they
// do. The stamps in `sc` belong to other nodes (or are -1), never to s.
bool disk_loop(const Topology& topo, int s, std::span<const int> faces, DiskScratch& sc) {
  int nv = 0, ne = 0;
  for (const int f : faces) {
    const Face& t = topo.faces()[f];
    for (int k = 0; k < 3; ++k) {
      const int a = t[k];
      if (sc.vstamp[a] != s) {
        sc.vstamp[a] = s;
        ++nv;
      }
      const int e = topo.face_edges(f)[k];
      if (sc.estamp[e] != s) {
        sc.estamp[e] = s;
        sc.ecount[e] = 1;
        sc.efrom[e] = a;
        ++ne;
      } else {
        ++sc.ecount[e];
        // Manifold and consistently oriented: an inner edge is used twice, in opposite senses.
        if (sc.ecount[e] > 2 || sc.efrom[e] == a) return false;
      }
    }
  }
  if (nv - ne + static_cast<int>(faces.size()) != 1) return false;
  int nb = 0, start = -1;
  for (const int f : faces) {
    const Face& t = topo.faces()[f];
    for (int k = 0; k < 3; ++k) {
      const int e = topo.face_edges(f)[k];
      if (sc.ecount[e] != 1) continue;
      const int a = t[k], b = t[(k + 1) % 3];
      if (sc.outstamp[a] == s) return false;  // a boundary vertex touched twice: a pinch
      sc.outstamp[a] = s;
      sc.next[a] = b;
      if (start < 0) start = a;
      ++nb;
    }
  }
  if (nb < 3) return false;
  const std::size_t first = sc.loops.size();
  int v = start;
  do {
    sc.loops.push_back(v);
    if (sc.outstamp[v] != s || static_cast<int>(sc.loops.size() - first) > nb) return false;
    v = sc.next[v];
  } while (v != start);
  return static_cast<int>(sc.loops.size() - first) == nb;
}

}  // namespace

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
  // Each pair of faces of an edge is one join; an edge's joins are independent of the others',
  // so they are found in parallel, then grouped by node (counting sort). Within a node the order
  // of the merges does not change how many succeed.
  struct Join {
    int f, g;
  };
  const int ne = topo.num_edges();
  std::vector<int> edge_joins(ne + 1, 0);
  for (int e = 0; e < ne; ++e) {
    const int k = static_cast<int>(topo.edge_faces(e).size());
    edge_joins[e + 1] = edge_joins[e] + k * (k - 1) / 2;
  }
  std::vector<int> join_node(edge_joins[ne]);
  std::vector<Join> join_faces(edge_joins[ne]);
  tbb::parallel_for(tbb::blocked_range<int>(0, ne, 4096), [&](const tbb::blocked_range<int>& r) {
    for (int e = r.begin(); e != r.end(); ++e) {
      const auto ef = topo.edge_faces(e);
      int at = edge_joins[e];
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
          join_node[at] = i;
          join_faces[at++] = {ef[x], ef[y]};
        }
      }
    }
  });
  std::vector<int> node_joins(nn + 1, 0);
  for (int i : join_node)
    ++node_joins[i + 1];
  std::partial_sum(node_joins.begin(), node_joins.end(), node_joins.begin());
  std::vector<Join> joins(join_faces.size());
  {
    std::vector<int> cursor(node_joins.begin(), node_joins.end() - 1);
    for (std::size_t j = 0; j < join_faces.size(); ++j)
      joins[cursor[join_node[j]]++] = join_faces[j];
  }
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
    for (int j = node_joins[i]; j < node_joins[i + 1]; ++j) {
      const int a = root(joins[j].f), b = root(joins[j].g);
      if (a == b) continue;
      parent[a] = b;
      --comps[i];
    }
    n.flags = comps[i] == 1 ? BvhNode::kConnected : 0;
  }

  // Disk test of connected internal nodes, in parallel: each thread has stamped scratch arrays
  // (no hashing) and keeps the loops it finds; they are then laid out in node order.
  tbb::enumerable_thread_specific<DiskScratch> scratch([&] { return DiskScratch(topo); });
  struct Found {
    const DiskScratch* in = nullptr;  // none: not a disk
    std::size_t at = 0, size = 0;
  };
  std::vector<Found> found(nn);
  tbb::parallel_for(tbb::blocked_range<int>(0, nn, 256), [&](const tbb::blocked_range<int>& r) {
    DiskScratch& sc = scratch.local();
    for (int i = r.begin(); i != r.end(); ++i) {
      BvhNode& n = nodes_[i];
      if (n.is_leaf() || !n.connected()) continue;
      const std::size_t at = sc.loops.size();
      const std::span<const int> faces(prim_ids_.data() + n.first,
                                       static_cast<std::size_t>(n.count));
      if (!disk_loop(topo, i, faces, sc)) {
        sc.loops.resize(at);
        continue;
      }
      n.flags |= BvhNode::kDisk;
      found[i] = {&sc, at, sc.loops.size() - at};
    }
  });
  contour_offsets_.assign(nn + 1, 0);
  contour_vertices_.clear();
  for (int i = 0; i < nn; ++i) {
    // The loops of all disk nodes together can outgrow the int offsets long before the face ids
    // do (a node's loop is counted at every level above its faces).
    contour_offsets_[i] = detail::checked_int(contour_vertices_.size(), "BVH contours");
    const Found& f = found[i];
    if (f.in == nullptr) continue;
    const auto first = f.in->loops.begin() + static_cast<std::ptrdiff_t>(f.at);
    contour_vertices_.insert(contour_vertices_.end(), first,
                             first + static_cast<std::ptrdiff_t>(f.size));
  }
  contour_offsets_[nn] = detail::checked_int(contour_vertices_.size(), "BVH contours");
}

}  // namespace clothcd
