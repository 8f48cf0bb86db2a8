// Extension dispatch and the frame-pair topology check.

#include <fmt/format.h>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
#include "io_util.hpp"

namespace clothcd {

TriangleMesh read_mesh(const std::filesystem::path& path) {
  const std::string ext = io_detail::lower_extension(path);
  if (ext == ".obj") return read_obj(path);
  if (ext == ".ply") return read_ply(path);
  throw input_error(path.string(), 0,
                    fmt::format("unknown mesh format '{}': expected .obj or .ply", ext));
}

void write_mesh(const std::filesystem::path& path, const TriangleMesh& mesh) {
  const std::string ext = io_detail::lower_extension(path);
  if (ext == ".obj") return write_obj(path, mesh);
  if (ext == ".ply") return write_ply(path, mesh);
  throw input_error(path.string(), 0,
                    fmt::format("unknown mesh format '{}': expected .obj or .ply", ext));
}

void check_same_topology(const TriangleMesh& a, const std::filesystem::path& path_a,
                         const TriangleMesh& b, const std::filesystem::path& path_b) {
  if (a.num_vertices() != b.num_vertices()) {
    throw InputError(
        fmt::format("{} has {} vertices but {} has {}: expected two frames of one "
                    "mesh",
                    path_a.string(), a.num_vertices(), path_b.string(), b.num_vertices()));
  }
  if (a.num_faces() != b.num_faces()) {
    throw InputError(fmt::format("{} has {} faces but {} has {}: expected two frames of one mesh",
                                 path_a.string(), a.num_faces(), path_b.string(), b.num_faces()));
  }
  for (int f = 0; f < a.num_faces(); ++f) {
    if (a.faces[f] != b.faces[f]) {
      throw InputError(fmt::format(
          "face {} differs: ({}, {}, {}) in {} but ({}, {}, {}) in {}: expected two frames of "
          "one mesh",
          f, a.faces[f][0], a.faces[f][1], a.faces[f][2], path_a.string(), b.faces[f][0],
          b.faces[f][1], b.faces[f][2], path_b.string()));
    }
  }
}

}  // namespace clothcd
