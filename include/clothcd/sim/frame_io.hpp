#pragma once
/// @file
/// Output of a simulation run: one mesh file per frame, the solver state of the last frame (for
/// `--resume`) and a manifest JSON; every file is written to a temporary name and renamed, so a
/// reader never sees a partial file.

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "clothcd/sim/integrator.hpp"
#include "clothcd/sim/simulation.hpp"

namespace clothcd::sim {

/// Writes `path` by calling `write` on a temporary file, checking every byte reached the disk,
/// then renaming. Throws std::runtime_error naming the file (and "disk full?") on failure.
void write_file_atomic(const std::filesystem::path& path,
                       const std::function<void(std::ostream&)>& write);

/// Triangle mesh as OBJ (text, %.9g) or binary little-endian PLY (float32 positions).
void write_mesh_atomic(const std::filesystem::path& path, const std::vector<Vec3>& x,
                       const std::vector<Face>& faces, const std::string& format);

/// Exact binary state (positions, velocities, warm start, time) and its frame.
void write_state_atomic(const std::filesystem::path& path, const ClothState& state, int frame);
/// Throws InputError when the file is missing, truncated, or for another vertex count.
[[nodiscard]] ClothState read_state(const std::filesystem::path& path, int num_vertices,
                                    int& frame);

[[nodiscard]] nlohmann::json to_json(const FrameStats& s);

/// Runs a simulation into a folder: frame_NNNN.{obj,ply}, state_NNNN.bin (the last frame's, and
/// every `keep_states`-th), manifest.json. With `resume`, continues from the manifest's last
/// complete frame, or from the kept state of frame `resume_at`.
struct RunOptions {
  std::filesystem::path out;
  int frames = -1;  ///< -1: the scene's count
  bool resume = false;
  /// Also keep the state of every frame that is a multiple of this (0: the last frame's only),
  /// so that a later frame can be replayed without rerunning from frame 0.
  int keep_states = 0;
  /// With `resume`: continue from this frame (its state must have been kept) instead of the
  /// last; the manifest drops the later frames, and their mesh and state files are removed.
  int resume_at = -1;
  /// Called after every frame (progress display); may be empty.
  std::function<void(const FrameStats&, int total_frames)> on_frame;
};
/// Returns the frames simulated in this call. Throws InputError for a bad resume folder and
/// std::runtime_error when the output cannot be written.
std::vector<FrameStats> run_simulation(Simulation& sim, const RunOptions& options);

}  // namespace clothcd::sim
