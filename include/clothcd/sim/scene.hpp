#pragma once
/// @file
/// Scene files (JSON, see docs/simulator.md of this repository for the keys): the cloth (from an
/// OBJ prefix or a procedural grid), its material, the body (OBJ frame sequence or sphere), pins,
/// frames and substep rules. Strings may use `${CLOTHCD_DATA}`: the environment variable when
/// set, else `../shared/data` relative to the repository holding the scene (the scene file's
/// folder's parent). Other relative paths are relative to the scene file.

#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "clothcd/sim/body.hpp"
#include "clothcd/sim/cloth_model.hpp"
#include "clothcd/sim/contact_handler.hpp"
#include "clothcd/sim/integrator.hpp"

namespace clothcd::sim {

struct SubstepRule {
  int min = 4;
  int max = 32;
  double displacement = 0.04;  ///< one substep per this much body motion (m)
  /// Also one substep per this much cloth motion, from the fastest cloth vertex at the frame's
  /// start (0: off). With collisions, a vertex stopped by an impulse while its neighbour moves on
  /// stretches their edge by the distance moved in one substep, so this keeps it below the edge
  /// length.
  double cloth_displacement = 0.0;
  /// Which cloth speed the cloth rule uses: this quantile of the vertex speeds (1: the fastest).
  /// Below 1, a few vertices thrown fast by the response do not set the substep count for all.
  double cloth_speed_quantile = 1.0;
  /// n = clamp(max(ceil(body displacement in the frame / displacement),
  ///               ceil(cloth speed * frame time / cloth_displacement)), min, max)
  [[nodiscard]] int count(double body_displacement, double cloth_displacement_estimate = 0.0) const;
  /// The cloth speed the rule uses: the `cloth_speed_quantile` of |v| (nearest rank).
  [[nodiscard]] double cloth_speed(std::span<const Vec3> v) const;
};

struct Scene {
  std::string name;
  std::filesystem::path file;
  ClothMeshInput cloth;
  ClothMaterial material;
  SolverOptions solver;
  std::vector<PinGroup> pins;
  std::unique_ptr<Body> body;  ///< null: no body
  double frame_dt = 0.04;
  int frames = 120;
  SubstepRule substeps;
  std::string output_format = "obj";  ///< "obj" or "ply"
  /// The collision stage (`collisions` key); off when the scene has no such key.
  bool collisions = false;
  ContactOptions contact;
  /// Undo self crossings of the starting shape (`collisions.repair_initial_crossings`; only with
  /// self collisions): repair_self_crossings with a margin of 0.1 `thickness`.
  bool repair_initial_crossings = true;
  /// Count intersecting triangle pairs after every frame (`collisions.count_intersections`).
  bool count_intersections = true;
};

/// Reads and validates a scene. Throws clothcd::InputError naming the scene file and the key
/// (unknown keys, wrong types, missing files, bad values).
[[nodiscard]] Scene load_scene(const std::filesystem::path& file);
/// The same from the text of a scene file; `file` names the scene in messages and anchors
/// relative paths (it need not exist).
[[nodiscard]] Scene parse_scene_text(std::string_view json_text, const std::filesystem::path& file);

/// The `${CLOTHCD_DATA}` value for a scene file.
[[nodiscard]] std::filesystem::path data_root_for(const std::filesystem::path& scene_file);

}  // namespace clothcd::sim
