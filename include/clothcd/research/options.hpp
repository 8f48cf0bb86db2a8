#pragma once
/// @file
/// Research options of the self detector (research::DetectOptions, taken by research::SelfDetector
/// in clothcd/research/detector.hpp): settings that reproduce the paper's measurements (Han, Lee,
/// Lee and Ko, Eurographics 2021) and check a culling rule against unculled detection. A simulator
/// uses clothcd::SelfDetector instead: the unsound rules can miss collisions, and the other
/// options cost time without changing what Culling::None and Culling::Sound report.
/// clothcd/research/names.hpp names every setting, research ones included, as the command-line
/// tool, the Python module and the experiment spell them.

#include <cstdint>
#include <optional>
#include <vector>

#include "clothcd/detect/types.hpp"

namespace clothcd::research {

/// Every culling rule the measurements compare, as one value: Culling::None and Sound, and two
/// rules that can miss collisions (docs/detect.md), for measuring how much the paper's rule culls
/// and what it misses against Sound, which finds all that None finds.
enum class CullingRule {
  None,   ///< Culling::None
  Cone,   ///< unsound: the paper's literal rule, skip a node's self test when its cone is below
          ///< pi/2. Misses contacts between parts of a node that face the same way without
          ///< touching along an edge (two stacked sheets) and within a patch that winds over itself
  Gated,  ///< unsound: the cone rule on edge-connected nodes only. Still misses contacts: a
          ///< connected patch can wind over itself (winding_strip in
          ///< clothcd/research/procedural.hpp)
  Sound,  ///< Culling::Sound
};
/// Whether `rule` can miss collisions (Cone, Gated).
[[nodiscard]] constexpr bool unsound(CullingRule rule) {
  return rule == CullingRule::Cone || rule == CullingRule::Gated;
}
/// ConePolicy's three policies, and the optimal reference cones (Options::optimal_cones).
enum class ConeRule { Provot, Proposed, Exact, Optimal };

struct Options {
  /// When set, the rule the detector runs instead of DetectOptions::culling's; the unsound rules
  /// are set here only (set_culling_rule in clothcd/research/names.hpp). An unsound rule is
  /// refused with a reuse distance: it may cull the pairs the distance keeps.
  std::optional<CullingRule> culling;
  /// Optimal node cones (the minimal cone of every descendant triangle's normal control
  /// directions, from exact leaf caps) instead of DetectOptions::policy's merges: the reference
  /// the policies are measured against. A node's cone costs time linear in its triangles, so a
  /// refit takes seconds on 100K triangles.
  bool optimal_cones = false;
  /// Also run the unculled traversal and narrow phase on the same step and report in
  /// DetectResult::verification what the culled detection missed. The step then costs about a
  /// culled and an unculled detection together. Nothing is run when the rule run is
  /// CullingRule::None.
  bool verify = false;
  bool operator==(const Options&) const = default;
};

/// What Options::verify found (research::DetectResult::verification).
struct Verification {
  bool ran = false;  ///< verify was set and a culling rule ran; otherwise the rest is empty
  /// Collisions the unculled detection reports and the culled one does not, sorted like
  /// DetectResult::vf and ee. Always empty with Culling::Sound.
  std::vector<VertexFaceCollision> missed_vf;
  std::vector<EdgeEdgeCollision> missed_ee;
  std::uint64_t unculled_triangle_pairs = 0;  ///< triangle pairs of the unculled traversal
};

/// The product's options and the research ones.
struct DetectOptions : clothcd::DetectOptions {
  DetectOptions() = default;
  DetectOptions(const clothcd::DetectOptions& o) : clothcd::DetectOptions(o) {}  // NOLINT: implicit
  Options research;
  bool operator==(const DetectOptions&) const = default;
};

/// A detection's results, and what Options::verify found.
struct DetectResult : clothcd::DetectResult {
  Verification verification;
};

}  // namespace clothcd::research
