#include "clothcd/mesh/topology.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <limits>
#include <numeric>
#include <utility>

#include "clothcd/core/error.hpp"

namespace clothcd {
namespace {

// Counting sort of (key, value) pairs into CSR arrays; values keep their input order per key.
template <class Emit>
void build_csr(int num_keys, std::size_t num_items, Emit emit, std::vector<int>& offsets,
               std::vector<int>& ids) {
  offsets.assign(static_cast<std::size_t>(num_keys) + 1, 0);
  emit([&](int key, int) { ++offsets[static_cast<std::size_t>(key) + 1]; });
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  ids.resize(num_items);
  std::vector<int> cursor(offsets.begin(), offsets.end() - 1);
  emit([&](int key, int value) { ids[static_cast<std::size_t>(cursor[key]++)] = value; });
}

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];  // path halving
    x = parent[x];
  }
  return x;
}

}  // namespace

void validate_faces(std::span<const Face> faces, int num_vertices) {
  if (num_vertices < 0) {
    throw InputError(fmt::format("topology: vertex count {} is negative", num_vertices));
  }
  // 3 * faces must fit an int (a Topology numbers the half-edges with ints).
  if (faces.size() > static_cast<std::size_t>(std::numeric_limits<int>::max() / 3)) {
    throw InputError(fmt::format("topology: {} faces exceed the supported maximum of {}",
                                 faces.size(), std::numeric_limits<int>::max() / 3));
  }
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const Face& t = faces[f];
    for (int k = 0; k < 3; ++k) {
      if (t[k] < 0 || t[k] >= num_vertices) {
        throw InputError(fmt::format(
            "face {} ({}, {}, {}): vertex index {} is out of range, expected 0 <= index < {}", f,
            t[0], t[1], t[2], t[k], num_vertices));
      }
    }
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      throw InputError(fmt::format(
          "face {} ({}, {}, {}) repeats a vertex, expected three distinct vertex indices", f, t[0],
          t[1], t[2]));
    }
  }
}

Topology::Topology(std::vector<Face> faces, int num_vertices)
    : num_vertices_(num_vertices), faces_(std::move(faces)) {
  validate_faces(faces_.get(), num_vertices_);
  const int nf = num_faces();

  // Half-edges keyed by (larger, smaller) vertex: in that order the unique edges come out already
  // in the cloth_ball numbering, and ties by half-edge id keep each edge's faces ascending. A
  // counting sort by the larger vertex, then a sort of each vertex's few (smaller, id) words,
  // gives exactly that order without a comparison sort over all of them.
  struct HalfEdge {
    std::uint64_t key;
    int id;  // 3 * face + k
  };
  std::vector<int> bucket(static_cast<std::size_t>(num_vertices_) + 1, 0);
  for (const Face& t : faces_.get()) {
    for (int k = 0; k < 3; ++k)
      ++bucket[static_cast<std::size_t>(std::max(t[k], t[(k + 1) % 3])) + 1];
  }
  std::partial_sum(bucket.begin(), bucket.end(), bucket.begin());
  std::vector<std::uint64_t> words(static_cast<std::size_t>(nf) * 3);  // smaller << 32 | id
  {
    std::vector<int> cursor(bucket.begin(), bucket.end() - 1);
    for (int f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) {
        const int a = faces_.get()[f][k], b = faces_.get()[f][(k + 1) % 3];
        words[static_cast<std::size_t>(cursor[std::max(a, b)]++)] =
            static_cast<std::uint64_t>(std::min(a, b)) << 32 |
            static_cast<std::uint64_t>(3 * f + k);
      }
    }
  }
  std::vector<HalfEdge> half(words.size());
  for (int v = 0; v < num_vertices_; ++v) {
    const auto first = words.begin() + bucket[v], last = words.begin() + bucket[v + 1];
    if (last - first > 32) {
      std::sort(first, last);
    } else {
      for (auto i = first; i != last; ++i) {  // insertion sort: few words, no allocation
        for (auto j = i; j != first && *j < *(j - 1); --j)
          std::iter_swap(j, j - 1);
      }
    }
    for (auto it = first; it != last; ++it) {
      half[static_cast<std::size_t>(it - words.begin())] = {
          static_cast<std::uint64_t>(v) << 32 | (*it >> 32), static_cast<int>(*it & 0xffffffffu)};
    }
  }

  face_edges_.assign(static_cast<std::size_t>(nf), {-1, -1, -1});
  edge_face_offsets_.clear();
  edge_face_ids_.clear();
  edge_face_ids_.reserve(half.size());
  for (std::size_t i = 0; i < half.size(); ++i) {
    if (i == 0 || half[i].key != half[i - 1].key) {
      edge_face_offsets_.push_back(static_cast<int>(edge_face_ids_.size()));
      edges_.push_back(
          {static_cast<int>(half[i].key & 0xffffffffu), static_cast<int>(half[i].key >> 32)});
    }
    const int e = static_cast<int>(edges_.size()) - 1;
    const int f = half[i].id / 3;
    face_edges_[f][half[i].id % 3] = e;
    // A duplicate face lists the edge again; a face cannot list it twice (distinct vertices).
    edge_face_ids_.push_back(f);
  }
  edge_face_offsets_.push_back(static_cast<int>(edge_face_ids_.size()));

  const int ne = num_edges();
  for (int e = 0; e < ne; ++e) {
    const int count = edge_face_offsets_[e + 1] - edge_face_offsets_[e];
    if (count == 1) ++num_boundary_edges_;
    if (count > 2) ++num_nonmanifold_edges_;
  }

  build_csr(
      num_vertices_, static_cast<std::size_t>(nf) * 3,
      [&](auto&& put) {
        for (int f = 0; f < nf; ++f) {
          for (int v : faces_.get()[f])
            put(v, f);
        }
      },
      vertex_face_offsets_, vertex_face_ids_);
  build_csr(
      num_vertices_, static_cast<std::size_t>(ne) * 2,
      [&](auto&& put) {
        for (int e = 0; e < ne; ++e) {
          put(edges_[e][0], e);
          put(edges_[e][1], e);
        }
      },
      vertex_edge_offsets_, vertex_edge_ids_);

  for (int v = 0; v < num_vertices_; ++v) {
    if (vertex_face_offsets_[v] == vertex_face_offsets_[v + 1]) ++num_isolated_vertices_;
  }

  // Duplicates: faces with the same vertex set as an earlier face, whatever their orientation.
  // Such a face g holds f's first edge, so it is among that edge's faces, and holds f's third
  // corner too.
  for (int f = 0; f < nf; ++f) {
    const Face& t = faces_.get()[f];
    for (int g : edge_faces(face_edges_[f][0])) {
      const Face& u = faces_.get()[g];
      if (g < f && (u[0] == t[2] || u[1] == t[2] || u[2] == t[2])) {
        ++num_duplicate_faces_;
        break;
      }
    }
  }

  // Edge-connected components by union-find, numbered by their smallest face.
  std::vector<int> parent(static_cast<std::size_t>(nf));
  std::iota(parent.begin(), parent.end(), 0);
  for (int e = 0; e < ne; ++e) {
    const int first = edge_face_ids_[edge_face_offsets_[e]];
    for (int i = edge_face_offsets_[e] + 1; i < edge_face_offsets_[e + 1]; ++i) {
      const int a = find_root(parent, first), b = find_root(parent, edge_face_ids_[i]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  face_component_.assign(static_cast<std::size_t>(nf), -1);
  std::vector<int> root_component(static_cast<std::size_t>(nf), -1);
  for (int f = 0; f < nf; ++f) {
    const int r = find_root(parent, f);
    if (root_component[r] < 0) root_component[r] = num_components_++;
    face_component_[f] = root_component[r];
  }
}

int Topology::find_edge(int a, int b) const {
  if (a < 0 || b < 0 || a >= num_vertices_ || b >= num_vertices_ || a == b) return -1;
  // vertex_edges(a) is ascending by edge id, and edge ids sort by (larger, smaller): edges (a, s)
  // with s < a come first ordered by s, then edges (x, a) with x > a ordered by x. So the list is
  // ordered by the other endpoint and a binary search finds b.
  const auto list = vertex_edges(a);
  const auto other = [&](int e) { return edges_[e][0] == a ? edges_[e][1] : edges_[e][0]; };
  const auto it =
      std::partition_point(list.begin(), list.end(), [&](int e) { return other(e) < b; });
  return (it != list.end() && other(*it) == b) ? *it : -1;
}

bool Topology::faces_share_vertex(int f, int g) const {
  for (int a : faces_.get()[f]) {
    for (int b : faces_.get()[g]) {
      if (a == b) return true;
    }
  }
  return false;
}

std::vector<int> Topology::face_neighbors(int f) const {
  std::vector<int> out;
  for (int e : face_edges_[f]) {
    for (int g : edge_faces(e)) {
      if (g != f) out.push_back(g);
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<std::uint8_t> Topology::faces_touching(
    std::span<const std::uint8_t> vertex_flags) const {
  std::vector<std::uint8_t> out(faces_.get().size(), 0);
  for (std::size_t f = 0; f < faces_.get().size(); ++f) {
    for (int v : faces_.get()[f])
      out[f] |= vertex_flags[v];
  }
  return out;
}

std::vector<std::uint8_t> Topology::edges_touching(
    std::span<const std::uint8_t> vertex_flags) const {
  std::vector<std::uint8_t> out(edges_.size(), 0);
  for (std::size_t e = 0; e < edges_.size(); ++e)
    out[e] = vertex_flags[edges_[e][0]] | vertex_flags[edges_[e][1]];
  return out;
}

std::vector<Face> to_faces(const Eigen::Ref<const Eigen::MatrixX3i>& faces) {
  std::vector<Face> out(static_cast<std::size_t>(faces.rows()));
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    out[f] = {faces(f, 0), faces(f, 1), faces(f, 2)};
  return out;
}

}  // namespace clothcd
