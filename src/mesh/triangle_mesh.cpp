#include "clothcd/mesh/triangle_mesh.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <string>

#include "clothcd/core/error.hpp"

namespace clothcd {

Eigen::MatrixX3d vertices_matrix(const TriangleMesh& mesh) {
  Eigen::MatrixX3d out(mesh.vertices.size(), 3);
  for (Eigen::Index i = 0; i < out.rows(); ++i)
    out.row(i) = mesh.vertices[i].transpose();
  return out;
}

Eigen::MatrixX3i faces_matrix(const TriangleMesh& mesh) {
  Eigen::MatrixX3i out(mesh.faces.size(), 3);
  for (Eigen::Index i = 0; i < out.rows(); ++i) {
    out.row(i) << mesh.faces[i][0], mesh.faces[i][1], mesh.faces[i][2];
  }
  return out;
}

TriangleMesh mesh_from_matrices(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& faces) {
  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<std::size_t>(vertices.rows()));
  for (Eigen::Index i = 0; i < vertices.rows(); ++i)
    mesh.vertices[i] = vertices.row(i).transpose();
  mesh.faces.resize(static_cast<std::size_t>(faces.rows()));
  for (Eigen::Index i = 0; i < faces.rows(); ++i) {
    mesh.faces[i] = {faces(i, 0), faces(i, 1), faces(i, 2)};
  }
  return mesh;
}

void validate_mesh(const TriangleMesh& mesh, std::string_view what) {
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!mesh.vertices[v].allFinite()) {
      throw InputError(fmt::format("{}: vertex {} has a non-finite coordinate ({}, {}, {})", what,
                                   v, mesh.vertices[v].x(), mesh.vertices[v].y(),
                                   mesh.vertices[v].z()));
    }
  }
  try {
    validate_faces(mesh.faces, mesh.num_vertices());
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", what, e.what()));
  }
}

TriangleMesh submesh_prefix(const TriangleMesh& mesh, int num_vertices, int num_faces) {
  if (num_vertices < 0 || num_vertices > mesh.num_vertices() || num_faces < 0 ||
      num_faces > mesh.num_faces()) {
    throw InputError(fmt::format(
        "submesh_prefix: asked for {} vertices and {} faces of a mesh with {} vertices and {} "
        "faces",
        num_vertices, num_faces, mesh.num_vertices(), mesh.num_faces()));
  }
  TriangleMesh out;
  out.vertices.assign(mesh.vertices.begin(), mesh.vertices.begin() + num_vertices);
  out.faces.assign(mesh.faces.begin(), mesh.faces.begin() + num_faces);
  for (int f = 0; f < num_faces; ++f) {
    for (int v : out.faces[f]) {
      if (v < 0 || v >= num_vertices) {
        throw InputError(
            fmt::format("submesh_prefix: face {} uses vertex {}, outside the first {} vertices", f,
                        v, num_vertices));
      }
    }
  }
  return out;
}

std::vector<int> zero_area_faces(const TriangleMesh& mesh, double max_area) {
  std::vector<int> out;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto& t = mesh.faces[f];
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const double area = 0.5 * (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
    if (area <= max_area) out.push_back(f);
  }
  return out;
}

}  // namespace clothcd
