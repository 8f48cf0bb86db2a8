#pragma once
/// @file
/// A small OBJ reader for the simulator's inputs: `v`, `vt`, `f` (v, v/vt, v//vn, v/vt/vn,
/// negative indices; polygons fanned) and the garment files' `stitch i j k r` lines.

#include <filesystem>
#include <vector>

#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim {

struct ObjData {
  std::vector<Vec3> positions;
  std::vector<Vec2> texcoords;
  std::vector<Face> faces;
  std::vector<Face> face_texcoords;  ///< per face corner, -1 when absent
  std::vector<Stitch> stitches;
};

/// Throws clothcd::InputError "file:line: what" on malformed lines or indices out of range.
[[nodiscard]] ObjData read_obj(const std::filesystem::path& file);

/// Only the `v` lines (fast path for animation frames).
[[nodiscard]] std::vector<Vec3> read_obj_positions(const std::filesystem::path& file);

}  // namespace clothcd::sim
