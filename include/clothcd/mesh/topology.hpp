#pragma once
/// @file
/// Connectivity of a triangle mesh: unique edges, incidences, adjacency, components.
/// Built once from the faces; positions live elsewhere (they change every step).

#include <Eigen/Core>

#include <array>
#include <cassert>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace clothcd {

using Face = std::array<int, 3>;
using Edge = std::array<int, 2>;  ///< (smaller vertex id, larger vertex id)

/// Rows of an m x 3 integer matrix (libigl's F) as faces; ids are checked where a Topology is
/// made.
[[nodiscard]] std::vector<Face> to_faces(const Eigen::Ref<const Eigen::MatrixX3i>& faces);

/// The checks a Topology makes of its input, without building it: throws clothcd::InputError
/// naming the face for a vertex index outside [0, num_vertices) or a face repeating a vertex.
void validate_faces(std::span<const Face> faces, int num_vertices);

/// Validated topology. Construction throws clothcd::InputError naming the face and what is wrong
/// for an index out of range or a face that repeats a vertex. Duplicate faces and non-manifold
/// edges are allowed and counted.
class Topology {
 public:
  Topology() = default;
  Topology(std::vector<Face> faces, int num_vertices);

  [[nodiscard]] int num_vertices() const { return num_vertices_; }
  [[nodiscard]] int num_faces() const { return static_cast<int>(faces().size()); }
  [[nodiscard]] int num_edges() const { return static_cast<int>(edges_.size()); }

  [[nodiscard]] const std::vector<Face>& faces() const { return faces_.get(); }
  /// The same faces, shared (they never change): a tree built from this topology keeps them
  /// without a copy of its own.
  [[nodiscard]] const std::shared_ptr<const std::vector<Face>>& shared_faces() const {
    return faces_.ptr();
  }
  /// Unique undirected edges, sorted by (larger id, smaller id): the numbering of the
  /// cloth_ball candidate files.
  [[nodiscard]] const std::vector<Edge>& edges() const { return edges_; }

  /// Edge ids of face f: edge k joins faces()[f][k] and faces()[f][(k + 1) % 3].
  [[nodiscard]] const std::array<int, 3>& face_edges(int f) const { return face_edges_[f]; }
  /// Faces incident to edge e (1 on a boundary, 2 inside, more when non-manifold).
  [[nodiscard]] std::span<const int> edge_faces(int e) const {
    return csr_row(edge_face_offsets_, edge_face_ids_, e);
  }
  /// Faces incident to vertex v, ascending.
  [[nodiscard]] std::span<const int> vertex_faces(int v) const {
    return csr_row(vertex_face_offsets_, vertex_face_ids_, v);
  }
  /// Edges incident to vertex v, ascending.
  [[nodiscard]] std::span<const int> vertex_edges(int v) const {
    return csr_row(vertex_edge_offsets_, vertex_edge_ids_, v);
  }
  /// Id of the edge joining a and b, or -1.
  [[nodiscard]] int find_edge(int a, int b) const;

  /// Edge-connected component of each face (faces sharing an edge are connected), 0-based and
  /// numbered in order of their smallest face id.
  [[nodiscard]] int num_components() const { return num_components_; }
  [[nodiscard]] int face_component(int f) const { return face_component_[f]; }

  /// True when faces f and g share at least one vertex.
  [[nodiscard]] bool faces_share_vertex(int f, int g) const;
  /// Faces other than f sharing an edge with f, ascending and unique.
  [[nodiscard]] std::vector<int> face_neighbors(int f) const;
  /// One flag per face (edge): set when one of its vertices is flagged in `vertex_flags` (one
  /// per vertex).
  [[nodiscard]] std::vector<std::uint8_t> faces_touching(
      std::span<const std::uint8_t> vertex_flags) const;
  [[nodiscard]] std::vector<std::uint8_t> edges_touching(
      std::span<const std::uint8_t> vertex_flags) const;

  [[nodiscard]] int num_boundary_edges() const { return num_boundary_edges_; }
  [[nodiscard]] int num_nonmanifold_edges() const { return num_nonmanifold_edges_; }
  [[nodiscard]] int num_duplicate_faces() const { return num_duplicate_faces_; }
  /// Vertices used by no face.
  [[nodiscard]] int num_isolated_vertices() const { return num_isolated_vertices_; }

 private:
  // Row i of a compressed sparse row table (inline: the setup's searches call these per feature).
  static std::span<const int> csr_row(const std::vector<int>& offsets, const std::vector<int>& ids,
                                      int i) {
    assert(i >= 0 && i + 1 < static_cast<int>(offsets.size()));
    return {ids.data() + offsets[i], static_cast<std::size_t>(offsets[i + 1] - offsets[i])};
  }

  // The faces, shared with the trees built from them; never null (a moved-from topology holds
  // an empty list, as a moved-from vector would).
  class SharedFaces {
   public:
    SharedFaces() : p_(none()) {}
    explicit SharedFaces(std::vector<Face> f)
        : p_(std::make_shared<const std::vector<Face>>(std::move(f))) {}
    SharedFaces(const SharedFaces&) = default;
    SharedFaces& operator=(const SharedFaces&) = default;
    SharedFaces(SharedFaces&& o) noexcept : p_(std::exchange(o.p_, none())) {}
    SharedFaces& operator=(SharedFaces&& o) noexcept {
      p_ = std::exchange(o.p_, none());
      return *this;
    }
    ~SharedFaces() = default;
    [[nodiscard]] const std::vector<Face>& get() const { return *p_; }
    [[nodiscard]] const std::shared_ptr<const std::vector<Face>>& ptr() const { return p_; }

   private:
    static std::shared_ptr<const std::vector<Face>> none() {
      static const auto empty = std::make_shared<const std::vector<Face>>();
      return empty;
    }
    std::shared_ptr<const std::vector<Face>> p_;
  };

  int num_vertices_ = 0;
  SharedFaces faces_;
  std::vector<Edge> edges_;
  std::vector<std::array<int, 3>> face_edges_;
  std::vector<int> edge_face_offsets_, edge_face_ids_;      // CSR
  std::vector<int> vertex_face_offsets_, vertex_face_ids_;  // CSR
  std::vector<int> vertex_edge_offsets_, vertex_edge_ids_;  // CSR
  std::vector<int> face_component_;
  int num_components_ = 0;
  int num_boundary_edges_ = 0;
  int num_nonmanifold_edges_ = 0;
  int num_duplicate_faces_ = 0;
  int num_isolated_vertices_ = 0;
};

}  // namespace clothcd
