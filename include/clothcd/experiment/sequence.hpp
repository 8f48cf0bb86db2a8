#pragma once
/// @file
/// Recorded motion for the experiment harness: one mesh topology and a list of frames; every
/// consecutive frame pair is one continuous collision detection call.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "clothcd/detect/detector.hpp"

namespace clothcd::experiment {

struct Sequence {
  std::string name;    ///< used in file names and tables (letters, digits, '-', '_', '.')
  std::string source;  ///< where the frames came from, for the reports
  std::vector<Face> faces;
  int num_vertices = 0;
  std::vector<Positions> frames;  ///< n x 3 each; frames.size() - 1 steps
  /// Self-crossing triangle pairs per frame (same length as `frames` once counted, see
  /// count_crossings), and how they were counted. Empty: not counted.
  std::vector<long long> crossings;
  std::string crossings_how;
  /// The experiment runs the CD calls 0, every, 2 every, ... (each one frame pair k -> k+1).
  int every = 1;

  [[nodiscard]] int steps() const { return frames.empty() ? 0 : int(frames.size()) - 1; }
};

/// Reads a folder of frames: the simulator's `manifest.json` + `frame_NNNN.{obj,ply}`, or else
/// every .obj/.ply file of the folder ordered by the number at the end of its name (the
/// cloth-ball data: cloth_ball92.ply, cloth_ball93.ply). At most `max_frames` frames (< 0: all).
/// Throws InputError for a folder without frames or frames of different topologies.
[[nodiscard]] Sequence load_frame_folder(const std::filesystem::path& dir, int max_frames = -1,
                                         std::string name = {});

/// Simulates a scene file into `out` (resuming what is there) until it holds `frames` frames
/// (< 0: the scene's count), then loads them. `on_frame(done, total)` reports progress.
[[nodiscard]] Sequence simulate_scene(const std::filesystem::path& scene_file,
                                      const std::filesystem::path& out, int frames,
                                      const std::function<void(int, int)>& on_frame = {});

/// Fills `crossings` if it is empty: intersecting non-adjacent triangle pairs of every frame, by
/// the simulator's intersection check (clothcd/sim/intersections.hpp, no seam links). Simulated
/// folders come with the simulator's own per-frame counts (which skip stitched pairs), read by
/// load_frame_folder.
void count_crossings(Sequence& seq);

/// Drops the frames before `first` (and their crossing counts); the sequence keeps its name.
void drop_frames_before(Sequence& seq, int first);

/// A procedural sequence: an n x n sheet (2 n^2 triangles) with a ripple; its far half folds
/// about the middle line onto the near half (0 to 180 degrees over the first half of the steps),
/// then its ripple travels, so the two layers keep passing through each other: every step after
/// the fold carries self-collisions, some between disconnected layers.
[[nodiscard]] Sequence folding_sheet(int n = 16, int steps = 6);

/// The single-step scenes of clothcd/research/procedural.hpp as one-step sequences, by name:
/// stacked_sheets, winding_strip, crumpled_sheet, twisted_strip; and `fold` (folding_sheet with
/// n = 40 and 12 steps). Throws InputError for another name.
[[nodiscard]] Sequence procedural_sequence(const std::string& name);
[[nodiscard]] std::vector<std::string> procedural_names();

}  // namespace clothcd::experiment
