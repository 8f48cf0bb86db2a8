#pragma once
/// @file
/// Options, collisions and statistics of the collision detection pipeline.

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/detect/collisions.hpp"
#include "clothcd/mesh/topology.hpp"

namespace clothcd {

/// When the self traversal may skip a node's self-collision test (docs/detect.md).
enum class Culling {
  None,   ///< boxes only
  Sound,  ///< a node whose triangles form a disk skips its self test when its normal cone is
          ///< below pi/2 and its contour test passes (and, with a thickness or a reuse
          ///< distance, clearances keep its features out of reach): finds exactly what None finds
};

struct DetectOptions {
  ConePolicy policy = ConePolicy::Proposed;
  Culling culling = Culling::None;
  BvhBuild build = BvhBuild::Spatial;
  /// Contact distance h >= 0 (the thickness model, docs/detect.md "Thickness"):
  /// - reported: every VF / EE pair whose features come within Euclidean distance h of each other
  ///   at some time of the step (no false negatives);
  /// - certified by a hit: only that they came within sqrt(3) (h + 1e-6 L), L the pair's extent
  ///   (the kernels reject in the infinity norm, to the inclusion solver's tolerance), so a few
  ///   pairs slightly farther than h may be reported too;
  /// - boxes: every swept box grows by h / 2 on each side (rounded outwards), so two boxes overlap
  ///   whenever their features come within h in every coordinate.
  /// Culling::Sound stays exact at any thickness: it culls only nodes whose features provably stay
  /// out of that reach (docs/algorithms.md 1.6).
  double thickness = 0.0;
  /// Deforming NP filter before the kernels (applied at zero thickness only).
  bool np_filter = true;
  /// At zero thickness (with np_filter), the distance filter runs too, as it always does with a
  /// thickness: a triangle pair whose two faces provably never touch over the step is dropped
  /// before its feature pairs are tested (the whole-triangle bound, distance_filter_culls for a
  /// TriangleTriangleQuery; DetectStats::triangle_pairs_apart counts them), and a feature pair the
  /// NP filter keeps is dropped where distance_filter_culls (thickness 0, two bisections) proves
  /// its features apart (counted with the NP filter's culls). Every collision is still reported;
  /// since the kernels certify a hit to within their tolerance (see thickness), a near miss they
  /// would report may be dropped where a bound proves the features apart. Fewer feature tests and
  /// kernel searches; off, the narrow phase is the paper's (NP filter, then kernels).
  bool distance_filter = true;
  /// CcdOptions::fast_path of the kernels.
  bool fast_path = true;
  /// CcdOptions::toi_tolerance of the kernels: how closely a hit's time of impact is refined
  /// (always on the early side). A simulator's response rarely needs more than a few percent.
  double toi_tolerance = 1e-4;
  /// Bisections of the distance filter (`distance_filter_culls` depth) when thickness > 0: each
  /// level can cull near misses the whole-step bound cannot, before the costlier kernel runs.
  int distance_filter_depth = 0;
  /// A simulator's shortcut, results unchanged: when > 0, an unrestricted detect() widens its
  /// candidate boxes to at least this distance and keeps its triangle pairs, so that a following
  /// proximity(v, h) with h <= reuse_distance traverses only near the vertices whose position in v
  /// differs from theirs at t1 (all of them when over a quarter do).
  double reuse_distance = 0.0;
  /// Culling::Sound tests only nodes of at least this many triangles, and the refit computes
  /// cones for those only (RefitOptions::cone_min_triangles). A test on a smaller node can save
  /// few pairs and costs about as much as it saves; skipping it is always sound, so the results
  /// are the same at any value, only the culled-node counts change. 0: every node (the paper's
  /// rule).
  int cull_min_triangles = 0;
  /// A simulator's shortcut, results unchanged: each unrestricted detect() starts its traversal
  /// where the previous one stopped (its "front" of node pairs: the pairs whose boxes missed and
  /// the overlapping leaf pairs), not at the root, and keeps the new front for the next call.
  /// Between successive steps of a slowly moving mesh most of the front stays where it was, and
  /// the box tests above it are saved. The same triangle pairs reach the narrow phase, so the
  /// results are the same; the front costs 8 bytes per node pair (DetectStats::front_pairs).
  /// Restricted calls, proximity queries and detect_each() traverse as without it.
  bool reuse_front = false;
  /// Optional vertex pairs that count as one point (the two sides of a stitched seam): VF and EE
  /// pairs joining them are not tested, like pairs that share a vertex. Any order; duplicates
  /// allowed.
  std::vector<std::pair<int, int>> linked_vertices;
  bool operator==(const DetectOptions&) const = default;
};

/// Counters and times of one detection call (times in seconds).
struct DetectStats {
  std::uint64_t box_tests = 0;      ///< node-pair box tests of the traversal
  std::uint64_t nodes_culled = 0;   ///< self tests skipped by the culling rule
  std::uint64_t cone_tests = 0;     ///< internal self tests that evaluated the rule
  std::uint64_t contour_tests = 0;  ///< contour tests run (Sound)
  std::uint64_t contour_fails = 0;  ///< ... of which failed, so the cone could not cull
  std::uint64_t front_pairs = 0;  ///< node pairs of the front kept for the next call (reuse_front)
  int internal_nodes = 0;
  int connected_internal_nodes = 0;  ///< internal nodes whose triangles are edge-connected
  int disk_internal_nodes = 0;
  std::uint64_t adjacent_pairs = 0;  ///< overlapping vertex-sharing leaf pairs (left to orphans)
  std::uint64_t triangle_pairs = 0;  ///< non-adjacent triangle pairs reaching the narrow phase
  /// ... of which culled whole by the whole-triangle distance bound (thickness > 0, or
  /// DetectOptions::distance_filter), their features untested
  std::uint64_t triangle_pairs_apart = 0;
  std::uint64_t vf_tests = 0;  ///< VF feature pairs past the feature box test (incl. orphans)
  std::uint64_t ee_tests = 0;
  /// ... of which the filters culled: the NP filter (zero thickness), the distance filter (with a
  /// thickness, or after the NP filter with DetectOptions::distance_filter)
  std::uint64_t vf_np_culled = 0;
  std::uint64_t ee_np_culled = 0;
  std::uint64_t vf_orphans = 0;  ///< orphan feature pairs checked (all of them, every step)
  std::uint64_t ee_orphans = 0;
  std::uint64_t vf_collisions = 0;
  std::uint64_t ee_collisions = 0;
  double time_refit = 0;  ///< boxes and cones
  double time_traverse = 0;
  double time_narrow = 0;  ///< feature tests of the triangle pairs and the orphans

  [[nodiscard]] double connected_share() const {
    return internal_nodes > 0 ? double(connected_internal_nodes) / internal_nodes : 1.0;
  }
};

/// Settings of an earliest-impact query (SelfDetector::earliest_impact,
/// PairDetector::earliest_impact); the thickness, filters, links and restriction are the
/// detector's.
struct EarliestOptions {
  /// How much earlier than the first contact the reported time may be (> 0): the kernels refine
  /// the winning pair's time of impact to this.
  double toi_tolerance = 1e-6;
  /// The first time window searched, [0, first_window] (a power of two in (0, 1]); 0 picks it
  /// from the motion: the largest window in which no vertex moves farther than a quarter of the
  /// mesh's mean edge length. Only a window that holds no contact leads to the next one, which
  /// starts where it ended and is four times as long (the last ends at 1). Results never depend
  /// on the thread count; they may differ between first windows by at most the tolerance above.
  double first_window = 0;
  bool operator==(const EarliestOptions&) const = default;
};

/// The earliest contact of one step: how far along the motion every feature pair stays farther
/// apart than the thickness.
struct EarliestImpact {
  enum class Kind : std::uint8_t { None, VertexFace, EdgeEdge };
  /// Never later than the first time at which a VF or EE pair comes within the thickness (moving
  /// every vertex to x0 + toi (x1 - x0) is safe), and no earlier than the first time at which
  /// that pair comes within sqrt(3) (thickness + 1e-6 L) (L the pair's extent; the kernels'
  /// certification), less toi_tolerance. 1 with Kind::None when no pair comes that close.
  double toi = 1.0;
  Kind kind = Kind::None;
  /// VertexFace: {vertex, face}; EdgeEdge: {edge_a, edge_b} (Topology edge ids; for one mesh
  /// edge_a < edge_b, between two meshes an edge of A and an edge of B); None: {-1, -1}. Of the
  /// pairs with the same toi, the one of smallest (kind, ids).
  std::array<int, 2> ids{-1, -1};
  /// Between two meshes (PairDetector), for VertexFace: the vertex is B's and the face A's.
  bool vertex_on_b = false;
  /// Time windows searched: [0, first_window], then [first_window, 4 first_window], ... up to
  /// the one that held the answer (or ended at 1).
  int windows = 0;
  double first_window = 1;
  /// Summed over the windows; the collision counts are the windows' hits (in a short window,
  /// the pairs its filters keep). time_narrow includes the timing and refinement of the hits,
  /// so the three times add up to the whole query.
  DetectStats stats;
};

struct DetectResult {
  std::vector<VertexFaceCollision> vf;  ///< sorted by (vertex, face)
  std::vector<EdgeEdgeCollision> ee;    ///< sorted by (edge_a, edge_b)
  DetectStats stats;
};

}  // namespace clothcd
