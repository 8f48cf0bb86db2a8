#pragma once
/// @file
/// Elementary continuous collision queries over one linear motion t in [0, 1]: a vertex against a
/// face (VF) and an edge against an edge (EE). Names follow ipc-toolkit: _t0/_t1 are the start and
/// end of the step.
///
/// Both kernels are conservative: they never miss a contact (docs/ccd.md gives the argument). A
/// hit certifies that the features came within sqrt(3) * (thickness + tolerance * L) of each other,
/// where L is the query's extent (largest coordinate range of its eight points).

#include <Eigen/Core>

#include <cstdint>

namespace clothcd {

struct VertexFaceQuery {
  Eigen::Vector3d v_t0, f0_t0, f1_t0, f2_t0;
  Eigen::Vector3d v_t1, f0_t1, f1_t1, f2_t1;
};

struct EdgeEdgeQuery {
  Eigen::Vector3d ea0_t0, ea1_t0, eb0_t0, eb1_t0;
  Eigen::Vector3d ea0_t1, ea1_t1, eb0_t1, eb1_t1;
};

/// Two triangles a and b moving linearly (for the whole-triangle distance filter).
struct TriangleTriangleQuery {
  Eigen::Vector3d a0_t0, a1_t0, a2_t0, b0_t0, b1_t0, b2_t0;
  Eigen::Vector3d a0_t1, a1_t1, a2_t1, b0_t1, b1_t1, b2_t1;
};

struct CcdOptions {
  /// Contact when the distance drops to this (>= 0). 0 is exact contact.
  double thickness = 0.0;
  /// Use the cubic fast path (Bernstein coplanarity cubic + NP filter) where it is well
  /// conditioned; false runs the conservative inclusion solver alone.
  bool fast_path = true;
  /// Relative size (times the query's extent) below which the inclusion solver stops splitting a
  /// box it cannot reject and reports a hit. Smaller: fewer false positives, more time.
  double tolerance = 1e-6;
  /// The reported time of impact is within this of the earliest box the solver could not reject
  /// (always on the early side). 0 refines it fully, which costs more on colliding queries.
  double toi_tolerance = 1e-4;
  /// Boxes the inclusion solver may visit per query; past it the query is reported as a hit with
  /// the earliest time still open (conservative, bounded time), unless a separating direction
  /// proves the features apart over the search's time range (docs/ccd.md).
  std::uint32_t max_boxes = 1u << 16;
};

/// Which part of the kernel decided a query.
enum class CcdPath : std::uint8_t {
  Trivial,    ///< decided before any solver (e.g. thickness larger than the query)
  NpCulled,   ///< the Bernstein coefficients of the coplanarity cubic share a sign
  FastPath,   ///< time ranges settled by the fast path, undecided ones by inclusion restricted to
              ///< them
  Inclusion,  ///< the inclusion solver over the whole of [0, 1]
  Certified,  ///< hit certified by the fast path: certain root, contact point certainly inside
};

struct CcdResult {
  bool hit = false;
  /// Conservative time of impact in [0, 1]: never later than the true first contact (1 when no
  /// hit).
  double toi = 1.0;
  /// Parameters of the hit box's centre (VF: barycentric weights of f1 and f2; EE: position along
  /// edge a and edge b); meaningful only when hit.
  double u = 0.0, v = 0.0;
  CcdPath path = CcdPath::Trivial;
  /// Boxes visited by the inclusion solver (0 when it did not run).
  std::uint32_t boxes = 0;
};

/// Zero false negatives: every query whose features come within `thickness` during the motion
/// reports a hit. NaN or infinite coordinates throw std::invalid_argument.
[[nodiscard]] CcdResult vertex_face_ccd(const VertexFaceQuery& q, const CcdOptions& opt = {});
[[nodiscard]] CcdResult edge_edge_ccd(const EdgeEdgeQuery& q, const CcdOptions& opt = {});

/// Deforming non-penetration filter (zero thickness only): true when the coplanarity cubic
/// provably has no root in [0, 1], so the pair cannot touch. Sound with a forward error bound.
[[nodiscard]] bool np_filter_culls(const VertexFaceQuery& q);
[[nodiscard]] bool np_filter_culls(const EdgeEdgeQuery& q);

/// Distance filter (any thickness): true when the features provably stay farther apart than
/// `thickness` during the whole motion. The distance is Lipschitz in t with constant D, the largest
/// relative displacement of a vertex of one feature against a vertex of the other, so it never
/// drops below (d0 + d1 - D) / 2 (d0, d1: the distances at both ends; docs/ccd.md). Cheap for
/// resting contact, where the cubic filter cannot help because thickness > 0. With `depth` > 0
/// the step is bisected (up to depth times, only where the bound fails and the distance at the
/// new instant still exceeds the thickness) and the bound applied to each part with its own end
/// distances: up to 2^depth + 1 distance evaluations that cull near misses the whole-step bound
/// cannot. The bound is first tried with the distances' cheap lower bounds
/// (point_triangle_distance_lower_bound, edge_edge_distance_lower_bound): where it culls with
/// them it culls with the distances, so the answer is the same. NaN or infinite coordinates throw
/// std::invalid_argument.
[[nodiscard]] bool distance_filter_culls(const VertexFaceQuery& q, double thickness, int depth = 0);
[[nodiscard]] bool distance_filter_culls(const EdgeEdgeQuery& q, double thickness, int depth = 0);
/// The distance filter for all 15 feature pairs (6 VF, 9 EE) of two triangles at once: the
/// whole-step bound with the triangles' distance lower bound
/// (triangle_triangle_distance_lower_bound) at both ends and D over all their vertices. Where
/// it culls, distance_filter_culls culls each feature pair (at any depth), so a narrow phase may
/// skip them all; it proves nothing where the triangles straddle each other's planes. NaN or
/// infinite coordinates throw std::invalid_argument.
[[nodiscard]] bool distance_filter_culls(const TriangleTriangleQuery& q, double thickness);

}  // namespace clothcd
