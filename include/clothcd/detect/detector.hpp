#pragma once
/// @file
/// The detector a simulator calls every step: continuous self-collision detection of one mesh
/// (BVH with a normal cone hierarchy, culling modes, R-triangles and orphan sets, NP filter,
/// CCD kernels), and inter-object detection between two meshes (cloth against body).

#include <Eigen/Core>

#include <memory>
#include <span>
#include <vector>

#include "clothcd/detect/types.hpp"

namespace clothcd {
namespace detail {
struct SelfCore;
struct SelfAccess;
}  // namespace detail

/// n x 3 vertex positions, one row per vertex.
///
/// Every call that takes positions has two forms:
/// - `const Positions&` (Eigen's default column-major matrix): read row by row;
/// - `std::span<const Eigen::Vector3d>` (e.g. a `std::vector<Eigen::Vector3d>`, or
///   `as_points(m)` of a row-major n x 3 matrix or a C-contiguous (n, 3) float64 NumPy array):
///   read straight from the caller's memory, with no intermediate matrix.
/// Both give the same results. Either way the detector copies the positions once into its own
/// arrays (it compares the next call's positions with them to redo only what moved), checks that
/// there are n of them and that they are finite, and keeps no reference to the caller's memory.
using Positions = Eigen::MatrixXd;

/// n x 3 row-major positions: the memory layout of a `std::vector<Eigen::Vector3d>` and of
/// NumPy's default (n, 3) float64 array.
using RowPositions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// The rows of a row-major n x 3 matrix as points, without a copy (valid while `m` lives).
[[nodiscard]] inline std::span<const Eigen::Vector3d> as_points(const RowPositions& m) {
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "Vector3d must be 3 packed doubles");
  return {reinterpret_cast<const Eigen::Vector3d*>(m.data()), static_cast<std::size_t>(m.rows())};
}

/// Proximity pairs: features closer than h at one instant (no cones: docs/algorithms.md 1.1).
struct ProximityResult {
  struct VertexFace {
    int vertex, face;
    double distance;
    friend bool operator==(const VertexFace&, const VertexFace&) = default;
  };
  struct EdgeEdge {
    int edge_a, edge_b;
    double distance;
    friend bool operator==(const EdgeEdge&, const EdgeEdge&) = default;
  };
  std::vector<VertexFace> vf;  ///< sorted by (vertex, face)
  std::vector<EdgeEdge> ee;    ///< sorted by (edge_a, edge_b)
  /// Triangle pairs taken from the last detect() instead of a traversal (see
  /// DetectOptions::reuse_distance); 0 when the query traversed the whole tree.
  std::size_t reused_pairs = 0;
};

class SelfDetector {
 public:
  /// Builds the topology, the orphan sets and the BVH (split on `reference`, e.g. the rest shape
  /// or the first frame). Throws InputError on bad faces or a reference of the wrong size.
  SelfDetector(std::vector<Face> faces, int num_vertices, const Positions& reference,
               const DetectOptions& options = {});
  SelfDetector(std::vector<Face> faces, int num_vertices,
               std::span<const Eigen::Vector3d> reference, const DetectOptions& options = {});
  /// Faces as an m x 3 integer matrix (libigl's F), one vertex per row of `reference` (its V).
  SelfDetector(const Eigen::Ref<const Eigen::MatrixX3i>& faces, const Positions& reference,
               const DetectOptions& options = {});
  ~SelfDetector();
  SelfDetector(SelfDetector&&) noexcept;
  SelfDetector& operator=(SelfDetector&&) noexcept;

  /// All VF and EE pairs that touch during the linear motion v_t0 -> v_t1 (CCD). Results are
  /// sorted and do not depend on the number of threads. The detector keeps the memory of the
  /// traversal's triangle pair list between calls (8 bytes a pair, at most the largest call's),
  /// so that a simulation's later calls allocate none.
  [[nodiscard]] DetectResult detect(const Positions& v_t0, const Positions& v_t1);
  [[nodiscard]] DetectResult detect(std::span<const Eigen::Vector3d> v_t0,
                                    std::span<const Eigen::Vector3d> v_t1);

  /// VF and EE pairs closer than h at positions v (box culling only), less the pairs that
  /// DetectOptions::linked_vertices join (as detect() leaves them out), within the active
  /// restriction like detect(). After a detect() with DetectOptions::reuse_distance >= h, it
  /// starts from that call's pairs (the same results).
  [[nodiscard]] ProximityResult proximity(const Positions& v, double h);
  [[nodiscard]] ProximityResult proximity(std::span<const Eigen::Vector3d> v, double h);

  /// How far along the linear motion v_t0 -> v_t1 every VF and EE pair stays farther apart than
  /// the thickness: the earliest time of impact, and the pair (EarliestImpact gives the
  /// guarantee). The pairs are the ones detect() tests (less linked pairs, within the active
  /// restriction), through detect()'s pipeline over time windows: a short window [0, T] first,
  /// then each next one four times as long, until one holds a contact (docs/detect.md "Earliest
  /// impact"). Does not depend on the thread count. Leaves what detect() keeps for later
  /// calls (DetectOptions::reuse_distance, reuse_front) as it was. Throws InputError for bad
  /// positions or options.
  [[nodiscard]] EarliestImpact earliest_impact(const Positions& v_t0, const Positions& v_t1,
                                               const EarliestOptions& options = {});
  [[nodiscard]] EarliestImpact earliest_impact(std::span<const Eigen::Vector3d> v_t0,
                                               std::span<const Eigen::Vector3d> v_t1,
                                               const EarliestOptions& options = {});

  /// The active restriction, which detect() and proximity() honour until clear_active() (or a
  /// rebuild()). A call of either setter replaces the restriction the other set.
  /// set_active_faces: pairs in which at least one feature belongs to an active triangle.
  void set_active_faces(std::span<const int> faces);
  /// set_active_vertices: pairs in which at least one vertex is active, exactly the pairs whose
  /// motion changes when only the active vertices move (a simulator's passes after the first).
  void set_active_vertices(std::span<const int> vertices);
  /// Lifts the active restriction, whichever setter made it.
  void clear_active();

  /// Builds the BVH afresh, split on `reference` (the same build kind). The tree is refit at
  /// every call but keeps the splits of the shape it was built on; once the mesh has deformed
  /// far from that shape its boxes are loose (Bvh::box_area_ratio() grows) and the traversals
  /// slow down. Results do not change. Clears an active restriction; keeps the pairs kept for
  /// reuse (DetectOptions::reuse_distance). Throws InputError for a reference of the wrong size.
  void rebuild(const Positions& reference);
  void rebuild(std::span<const Eigen::Vector3d> reference);

  [[nodiscard]] const DetectOptions& options() const;
  /// Replaces the options for the following calls. The BVH build is fixed at construction: an
  /// options.build other than options().build throws InputError (rebuild() keeps the build; a
  /// new detector takes another). Throws InputError as the constructor does.
  void set_options(const DetectOptions& options);
  [[nodiscard]] const Topology& topology() const;
  [[nodiscard]] const Bvh& bvh() const;

 private:
  friend struct detail::SelfAccess;
  std::unique_ptr<detail::SelfCore> impl_;
};

/// Collisions between two meshes A (e.g. a garment) and B (e.g. a body); no self-collisions.
struct PairDetectResult {
  std::vector<VertexFaceCollision> vf_a_on_b;  ///< vertex of A, face of B; sorted
  std::vector<VertexFaceCollision> vf_b_on_a;  ///< vertex of B, face of A; sorted
  std::vector<EdgeEdgeCollision> ee;           ///< edge_a of A, edge_b of B; sorted
  DetectStats stats;
};

/// Proximity pairs between two meshes: features of A and B closer than h at one instant.
struct PairProximityResult {
  std::vector<ProximityResult::VertexFace> vf_a_on_b;  ///< vertex of A, face of B; sorted
  std::vector<ProximityResult::VertexFace> vf_b_on_a;  ///< vertex of B, face of A; sorted
  std::vector<ProximityResult::EdgeEdge> ee;           ///< edge_a of A, edge_b of B; sorted
};

/// Detection between two meshes with the self detector's kernels and options: thickness (boxes
/// grow with it; above zero the distance filter with distance_filter_depth replaces the cubic NP
/// filter), np_filter, fast_path, toi_tolerance and build mean what they mean for SelfDetector.
/// Each feature pair is tested once; results are sorted and do not depend on the thread count.
class PairDetector {
 public:
  /// Builds both topologies and box-only BVHs (split on the references). Throws InputError on
  /// bad faces, a reference of the wrong size, or options it cannot honour between two meshes:
  /// a culling other than Culling::None (cones cull self tests only), reuse_distance other than
  /// 0, linked_vertices (they join vertices of one mesh), a negative thickness. policy and
  /// cull_min_triangles select nothing without cones.
  PairDetector(std::vector<Face> faces_a, int num_vertices_a, const Positions& reference_a,
               std::vector<Face> faces_b, int num_vertices_b, const Positions& reference_b,
               const DetectOptions& options = {});
  PairDetector(std::vector<Face> faces_a, int num_vertices_a,
               std::span<const Eigen::Vector3d> reference_a, std::vector<Face> faces_b,
               int num_vertices_b, std::span<const Eigen::Vector3d> reference_b,
               const DetectOptions& options = {});
  /// Faces as m x 3 integer matrices, one vertex per row of each reference.
  PairDetector(const Eigen::Ref<const Eigen::MatrixX3i>& faces_a, const Positions& reference_a,
               const Eigen::Ref<const Eigen::MatrixX3i>& faces_b, const Positions& reference_b,
               const DetectOptions& options = {});
  ~PairDetector();
  PairDetector(PairDetector&&) noexcept;
  PairDetector& operator=(PairDetector&&) noexcept;

  /// All VF and EE pairs between A and B that touch during the linear motions a_t0 -> a_t1 and
  /// b_t0 -> b_t1. A call after another detect() redoes only the boxes over moved vertices (the
  /// same results as from scratch): a simulator's later passes pay for what changed.
  [[nodiscard]] PairDetectResult detect(const Positions& a_t0, const Positions& a_t1,
                                        const Positions& b_t0, const Positions& b_t1);
  [[nodiscard]] PairDetectResult detect(std::span<const Eigen::Vector3d> a_t0,
                                        std::span<const Eigen::Vector3d> a_t1,
                                        std::span<const Eigen::Vector3d> b_t0,
                                        std::span<const Eigen::Vector3d> b_t1);

  /// VF and EE pairs between A and B closer than h at positions a and b, with their distances
  /// (box culling only); honours the active restriction like detect().
  [[nodiscard]] PairProximityResult proximity(const Positions& a, const Positions& b, double h);
  [[nodiscard]] PairProximityResult proximity(std::span<const Eigen::Vector3d> a,
                                              std::span<const Eigen::Vector3d> b, double h);

  /// The earliest time at which a VF or EE pair between A and B comes within the thickness
  /// during the motions (SelfDetector::earliest_impact between two meshes: the same guarantee;
  /// EarliestImpact::vertex_on_b tells the VF pairs' sides), within the active restriction.
  [[nodiscard]] EarliestImpact earliest_impact(const Positions& a_t0, const Positions& a_t1,
                                               const Positions& b_t0, const Positions& b_t1,
                                               const EarliestOptions& options = {});
  [[nodiscard]] EarliestImpact earliest_impact(std::span<const Eigen::Vector3d> a_t0,
                                               std::span<const Eigen::Vector3d> a_t1,
                                               std::span<const Eigen::Vector3d> b_t0,
                                               std::span<const Eigen::Vector3d> b_t1,
                                               const EarliestOptions& options = {});

  /// Restricts detect() and proximity() to pairs with an active vertex (ids of A and of B), until
  /// clear_active() (or a rebuild()): a VF pair when its vertex or a vertex of its face is active,
  /// an EE pair when an endpoint is active. Throws InputError for an id out of range.
  void set_active_vertices(std::span<const int> vertices_a, std::span<const int> vertices_b = {});
  /// Lifts the active restriction.
  void clear_active();

  /// Builds both BVHs afresh, split on the references (see SelfDetector::rebuild: results do not
  /// change, loose boxes of a tree refit far from its build shape cost time). Clears an active
  /// restriction. Throws InputError for a reference of the wrong size.
  void rebuild(const Positions& reference_a, const Positions& reference_b);
  void rebuild(std::span<const Eigen::Vector3d> reference_a,
               std::span<const Eigen::Vector3d> reference_b);

  [[nodiscard]] const DetectOptions& options() const;
  /// Throws InputError like the constructor, and for an options.build other than
  /// options().build (the build is fixed at construction, as for SelfDetector::set_options).
  void set_options(const DetectOptions& options);
  [[nodiscard]] const Topology& topology_a() const;
  [[nodiscard]] const Topology& topology_b() const;
  [[nodiscard]] const Bvh& bvh_a() const;
  [[nodiscard]] const Bvh& bvh_b() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothcd
