#pragma once
/// @file
/// Research options of the self detector (DetectOptions::research): settings that reproduce the
/// paper's measurements (Han, Lee, Lee and Ko, Eurographics 2021) and check a culling rule
/// against unculled detection. A simulator leaves them at their defaults: the unsound rules can
/// miss collisions, and the other options cost time without changing what Culling::None and
/// Culling::Sound report.
/// clothcd/research/names.hpp names every setting, research ones included, as the command-line
/// tool, the Python module and the experiment spell them.

#include <cstdint>
#include <vector>

#include "clothcd/detect/collisions.hpp"

namespace clothcd::research {

/// Culling rules that can miss collisions (docs/detect.md): for measuring how much the paper's
/// rule culls and what it misses against Culling::Sound, which finds all that Culling::None finds.
enum class UnsoundCulling {
  None,   ///< no override: DetectOptions::culling applies
  Cone,   ///< the paper's literal rule: skip a node's self test when its cone is below pi/2.
          ///< Misses contacts between parts of a node that face the same way without touching
          ///< along an edge (two stacked sheets) and within a patch that winds over itself
  Gated,  ///< the cone rule on edge-connected nodes only. Still misses contacts: a connected
          ///< patch can wind over itself (winding_strip in clothcd/detect/procedural.hpp)
};

struct Options {
  /// Overrides DetectOptions::culling when not None (the detector then runs this rule).
  UnsoundCulling unsound_culling = UnsoundCulling::None;
  /// Optimal node cones (the minimal cone of every descendant triangle's normal control
  /// directions, from exact leaf caps) instead of DetectOptions::policy's merges: the reference
  /// the policies are measured against. A node's cone costs time linear in its triangles, so a
  /// refit takes seconds on 100K triangles.
  bool optimal_cones = false;
  /// Also run the unculled traversal and narrow phase on the same step and report in
  /// DetectResult::verification what the culled detection missed. The step then costs about a
  /// culled and an unculled detection together. Nothing is run with Culling::None and no unsound
  /// rule.
  bool verify = false;
  bool operator==(const Options&) const = default;
};

/// What Options::verify found (DetectResult::verification).
struct Verification {
  bool ran = false;  ///< verify was set and a culling rule ran; otherwise the rest is empty
  /// Collisions the unculled detection reports and the culled one does not, sorted like
  /// DetectResult::vf and ee. Always empty with Culling::Sound.
  std::vector<VertexFaceCollision> missed_vf;
  std::vector<EdgeEdgeCollision> missed_ee;
  std::uint64_t unculled_triangle_pairs = 0;  ///< triangle pairs of the unculled traversal
};

}  // namespace clothcd::research
