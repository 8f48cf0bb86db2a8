#pragma once
/// @file
/// Output of a simulation run: one mesh file per frame, the solver state of the last frame (for
/// `--resume`) and a manifest JSON; every file goes through write_file_atomic
/// (clothcd/core/atomic_file.hpp), so a reader never sees a partial file, and the manifest,
/// written last for each frame, is the commit point a resume starts from.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "clothcd/core/atomic_file.hpp"
#include "clothcd/sim/integrator.hpp"
#include "clothcd/sim/simulation.hpp"

namespace clothcd::sim {

/// Exclusive use of a simulation's output folder for the object's life, so that two runs never
/// write one folder: `FOLDER/.lock` is locked with flock(2), which the kernel releases when the
/// process ends in any way (a killed run never blocks its resume). Creates the folder when
/// missing, and removes it again on release when nothing but the lock file was put in it.
/// Throws std::runtime_error naming the folder (and the holder's process id) when another process
/// holds it, and OutputError with the reason when the folder cannot be created or the lock file
/// opened or written (which finds a read-only folder before any work is done).
class OutputLock {
 public:
  explicit OutputLock(std::filesystem::path folder);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }

 private:
  void release() noexcept;
  std::filesystem::path folder_;
  int fd_ = -1;
  bool created_ = false;  ///< the folder did not exist before
  bool locked_ = false;
};

/// Triangle mesh as OBJ (text, %.9g) or binary little-endian PLY (float32 positions).
void write_mesh_atomic(const std::filesystem::path& path, const std::vector<Vec3>& x,
                       const std::vector<Face>& faces, const std::string& format);

/// Exact binary state (positions, velocities, warm start, time) and its frame.
void write_state_atomic(const std::filesystem::path& path, const ClothState& state, int frame);
/// Throws InputError when the file is missing, truncated, or for another vertex count.
[[nodiscard]] ClothState read_state(const std::filesystem::path& path, int num_vertices,
                                    int& frame);

/// One frame's statistics as a JSON object (text), as manifest.json lists them under "frames".
[[nodiscard]] std::string frame_stats_json(const FrameStats& s);

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
  /// The caller's lock on `out` (taken early, say, to refuse before a slow setup); when null,
  /// run_simulation locks `out` itself for the call.
  const OutputLock* lock = nullptr;
};
/// Returns the frames simulated in this call. Throws InputError for a bad resume folder,
/// std::runtime_error when another run holds the folder, and OutputError (a std::runtime_error)
/// naming the file and the reason when the output cannot be written; the files of the last
/// complete frame are then left as they were. Temporary files a killed run left are removed.
std::vector<FrameStats> run_simulation(Simulation& sim, const RunOptions& options);

}  // namespace clothcd::sim
