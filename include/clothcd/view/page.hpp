#pragma once
/// @file
/// The viewer page of `clothcd view`: one self-contained HTML file (three.js and the viewer's code
/// inlined, the geometry compressed inside it) that opens offline in a browser. Two kinds:
/// - a simulation: the output folder of `clothcd simulate` (manifest.json and the frame meshes),
///   the garment and the body at every frame, coloured by strain or by contact;
/// - a detection step: the two frames given to `clothcd detect` and its `--json` result, the
///   triangles of every hit highlighted and a list of the hits.
/// Everything is read and checked before anything is written; the page goes through the atomic
/// writer (clothcd/core/atomic_file.hpp), so a failure leaves no file, or the old one.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace clothcd::view {

struct SequenceOptions {
  int first = 0;        ///< first frame on the page
  int last = -1;        ///< last frame (-1: the last complete frame)
  int step = 1;         ///< every step-th frame
  bool body = true;     ///< the body, when the manifest's scene file can be read
  bool contact = true;  ///< per-frame contact flags (a proximity query per frame)
  /// Contact distance for the contact colouring; <= 0: the run's `contact.thickness` (or 2 mm
  /// when the run had no collisions).
  double contact_distance = 0.0;
};

/// What a page holds, for messages and tests.
struct PageSummary {
  std::size_t bytes = 0;         ///< size of the HTML file
  std::size_t data_bytes = 0;    ///< the geometry before compression
  std::size_t packed_bytes = 0;  ///< the geometry compressed (before base64)
  int frames = 0;                ///< frames (sequence) or 2 (detection)
  int hits = 0;                  ///< hits listed (detection)
  bool body = false;
  bool strain = false;
  bool contact = false;
  /// What the page leaves out and why (a scene file that cannot be read: no body, no strain).
  std::vector<std::string> notes;
};

/// The page of a `clothcd simulate` output folder. Throws InputError (folder, file, line, what
/// was expected) on a missing or bad manifest or frame, OutputError when `out` cannot be written.
PageSummary write_sequence_page(const std::filesystem::path& folder,
                                const std::filesystem::path& out,
                                const SequenceOptions& options = {});

/// The page of one detection step: meshes t0 and t1 (same topology) and the `clothcd detect
/// --json` result of that step. Throws InputError for bad meshes, a malformed result, or a hit
/// that names a vertex, face or edge the meshes do not have; OutputError when `out` cannot be
/// written.
PageSummary write_detection_page(const std::filesystem::path& t0, const std::filesystem::path& t1,
                                 const std::filesystem::path& result_json,
                                 const std::filesystem::path& out);

}  // namespace clothcd::view
