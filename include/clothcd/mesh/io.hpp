#pragma once
/// @file
/// Reading and writing triangle meshes (OBJ, PLY). Every reader validates its input and throws
/// clothcd::InputError naming the file, the line (text) or element (binary) and what was expected;
/// claimed counts are checked against the file size before anything is allocated. Writers are
/// atomic: a temporary file in the target's folder is renamed over the target once complete.
/// docs/formats.md lists the accepted syntax and every rejected input class.

#include <filesystem>
#include <vector>

#include "clothcd/mesh/triangle_mesh.hpp"

namespace clothcd {

/// A garment seam tie from a stage.obj `stitch i j k r` line (0-based): vertex i is tied to the
/// point (1 - r) x_j + r x_k of edge (j, k).
struct Stitch {
  int i = 0, j = 0, k = 0;
  double r = 0.0;
  friend bool operator==(const Stitch&, const Stitch&) = default;
};

/// An OBJ file's triangles (polygons fan-triangulated from their first corner, corner order kept),
/// its `stitch` lines and its texture coordinates (a garment's flat pattern). Normals, groups and
/// materials are ignored.
struct ObjContents {
  TriangleMesh mesh;
  std::vector<Stitch> stitches;
  std::vector<Eigen::Vector2d> texcoords;  ///< the `vt` lines (u v)
  /// Per face (as in mesh.faces), each corner's texture coordinate index, -1 where it names none.
  std::vector<Face> face_texcoords;
};

[[nodiscard]] ObjContents read_obj_with_stitches(const std::filesystem::path& path);
[[nodiscard]] TriangleMesh read_obj(const std::filesystem::path& path);
/// Only the `v` lines, checked as read_obj checks them; faces and other lines are skipped (the
/// later frames of an animation whose faces the first frame gave).
[[nodiscard]] std::vector<Eigen::Vector3d> read_obj_vertices(const std::filesystem::path& path);
/// PLY: ascii, binary_little_endian or binary_big_endian; see docs/formats.md.
[[nodiscard]] TriangleMesh read_ply(const std::filesystem::path& path);
/// Dispatches on the extension (.obj or .ply, any case).
[[nodiscard]] TriangleMesh read_mesh(const std::filesystem::path& path);

/// OBJ with shortest round-trip decimal coordinates (reads back bit-identical).
void write_obj(const std::filesystem::path& path, const TriangleMesh& mesh);
/// Binary little-endian PLY with double coordinates and uchar/int face lists.
void write_ply(const std::filesystem::path& path, const TriangleMesh& mesh);
/// Dispatches on the extension (.obj or .ply, any case).
void write_mesh(const std::filesystem::path& path, const TriangleMesh& mesh);

/// Two frames of one animation must share their topology: throws InputError naming both files
/// (and the first differing face) when the vertex counts or the faces differ.
void check_same_topology(const TriangleMesh& a, const std::filesystem::path& path_a,
                         const TriangleMesh& b, const std::filesystem::path& path_b);

}  // namespace clothcd
