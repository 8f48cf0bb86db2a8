#pragma once
/// @file
/// A triangle mesh as plain arrays, and conversions to the n x 3 matrices of the detector API
/// (the layout libigl and ipc-toolkit use).

#include <Eigen/Core>
#include <string_view>
#include <vector>

#include "clothcd/mesh/topology.hpp"

namespace clothcd {

/// Vertex positions and triangles (0-based vertex ids). A value type: copying copies the arrays.
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Face> faces;

  [[nodiscard]] int num_vertices() const { return static_cast<int>(vertices.size()); }
  [[nodiscard]] int num_faces() const { return static_cast<int>(faces.size()); }
  friend bool operator==(const TriangleMesh&, const TriangleMesh&) = default;
};

/// Vertices as rows of an n x 3 matrix.
[[nodiscard]] Eigen::MatrixX3d vertices_matrix(const TriangleMesh& mesh);
/// Faces as rows of an m x 3 matrix.
[[nodiscard]] Eigen::MatrixX3i faces_matrix(const TriangleMesh& mesh);
/// The mesh of the given rows (not validated; see validate_mesh).
[[nodiscard]] TriangleMesh mesh_from_matrices(const Eigen::MatrixX3d& vertices,
                                              const Eigen::MatrixX3i& faces);

/// Throws clothcd::InputError, naming `what` (a file name or "input") and the vertex or face, for
/// a non-finite coordinate, an index out of range or a face repeating a vertex.
void validate_mesh(const TriangleMesh& mesh, std::string_view what);

/// The first `num_vertices` vertices and `num_faces` faces (a drape.obj holds the garment first,
/// then the mannequin). Throws InputError when the counts exceed the mesh or a kept face uses a
/// dropped vertex.
[[nodiscard]] TriangleMesh submesh_prefix(const TriangleMesh& mesh, int num_vertices,
                                          int num_faces);

/// Faces whose area is at most `max_area` (0: exactly zero area, i.e. collinear or coincident
/// corners), ascending. Index validity is the topology's business; these are geometric
/// degeneracies a detector must tolerate.
[[nodiscard]] std::vector<int> zero_area_faces(const TriangleMesh& mesh, double max_area = 0.0);

}  // namespace clothcd
