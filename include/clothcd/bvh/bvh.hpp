#pragma once
/// @file
/// A binary BVH over a mesh's triangles (one triangle per leaf) with a normal cone hierarchy.
/// Built once from a reference shape; refit every step with swept boxes and normal cones.
/// Layout: a flat node array in breadth-first order (children adjacent, after their parent, each
/// depth contiguous so a refit runs level by level in parallel), a primitive permutation in which
/// every node covers one contiguous range, and the cones in an array beside the nodes.

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "clothcd/bvh/aabb.hpp"
#include "clothcd/geometry/cone.hpp"
#include "clothcd/mesh/topology.hpp"

namespace clothcd {

/// How the tree is split at build time.
enum class BvhBuild {
  Spatial,  ///< median split of triangle centroids along the longest axis
  Patch,    ///< every node an edge-connected patch where the mesh allows it
};

/// How node normal cones are computed at refit (docs/algorithms.md sections 3, 4, 8).
enum class ConePolicy {
  Provot,    ///< C_Tang leaves, M_Provot merges (the paper's PROVOT)
  Proposed,  ///< C_Proposed leaves, M_Proposed merges (the paper's PROPOSED)
  Exact,     ///< exact leaf caps, M_Proposed merges (ours)
};

/// One node: 64 bytes. Leaves hold exactly one triangle, prim_ids()[first].
struct BvhNode {
  std::array<double, 3> lo{};
  std::array<double, 3> hi{};
  std::int32_t left = -1;  ///< index of the first child (the second is left + 1); -1 for a leaf
  std::int32_t first = 0;  ///< first position of the node's triangles in prim_ids()
  std::int32_t count = 0;  ///< number of triangles below the node
  std::uint32_t flags = 0;

  static constexpr std::uint32_t kConnected = 1;  ///< triangles are edge-connected
  static constexpr std::uint32_t kDisk = 2;       ///< a consistently oriented topological disk

  [[nodiscard]] bool is_leaf() const { return left < 0; }
  [[nodiscard]] bool connected() const { return (flags & kConnected) != 0; }
  [[nodiscard]] bool disk() const { return (flags & kDisk) != 0; }
};
static_assert(sizeof(BvhNode) == 64, "BvhNode must stay one cache line");

/// Box overlap of two nodes (closed boxes): overlap(a.lo, a.hi, b.lo, b.hi), the traversals'
/// most frequent test. On x86-64 its six comparisons as three SSE2 comparisons of two lanes (the
/// same double comparisons, so the same answers, NaN included).
[[nodiscard]] inline bool overlap(const BvhNode& a, const BvhNode& b) {
#if defined(__SSE2__)
  // Lanes (lo0, lo1) <= (hi0, hi1) both ways, then (a.lo2, b.lo2) <= (b.hi2, a.hi2).
  const __m128d ab01 = _mm_cmple_pd(_mm_loadu_pd(a.lo.data()), _mm_loadu_pd(b.hi.data()));
  const __m128d ba01 = _mm_cmple_pd(_mm_loadu_pd(b.lo.data()), _mm_loadu_pd(a.hi.data()));
  const __m128d lo2 = _mm_loadh_pd(_mm_load_sd(&a.lo[2]), &b.lo[2]);
  const __m128d hi2 = _mm_loadh_pd(_mm_load_sd(&b.hi[2]), &a.hi[2]);
  const __m128d all = _mm_and_pd(_mm_and_pd(ab01, ba01), _mm_cmple_pd(lo2, hi2));
  return _mm_movemask_pd(all) == 3;
#else
  return overlap(a.lo, a.hi, b.lo, b.hi);
#endif
}

/// Options of a refit.
struct RefitOptions {
  double thickness = 0.0;  ///< boxes grow by thickness / 2 on every side (rounded outwards)
  bool cones = true;       ///< compute the normal cones (box-only traversal skips them)
  ConePolicy policy = ConePolicy::Proposed;
  /// CCD refits with cones fit cones only to nodes of at least this
  /// many triangles: such a node whose child is smaller gives that child a valid cone of its
  /// triangles' normals computed at once (not `policy`'s), and the nodes below get none
  /// (cones() keeps their last values). For a traversal that tests no smaller node's cone.
  /// 0 or 1: every node gets `policy`'s cone. Static refits ignore it.
  int cone_min_triangles = 0;
  bool operator==(const RefitOptions&) const = default;
};

namespace detail {
struct OptimalCones;
}

class Bvh {
 public:
  Bvh() = default;
  /// Builds over all faces of `topology` using the reference positions (n x 3) for the splits.
  /// The tree shares the topology's faces (Topology::shared_faces): it stays valid, and can be
  /// copied and moved, independently of `topology`. Large subtrees are built in parallel (oneTBB);
  /// the tree is the same for any number of threads.
  Bvh(const Topology& topology, std::span<const Eigen::Vector3d> reference, BvhBuild build);
  /// The same tree without the per-node topology flags and contours, which take about half of a
  /// build's time: for box-only traversals that rebuild their tree as the mesh deforms. Every
  /// node then reads as neither connected nor a disk (no cone culling) and has no contour.
  [[nodiscard]] static Bvh boxes_only(const Topology& topology,
                                      std::span<const Eigen::Vector3d> reference, BvhBuild build);

  [[nodiscard]] const std::vector<BvhNode>& nodes() const { return nodes_; }
  [[nodiscard]] const std::vector<int>& prim_ids() const { return prim_ids_; }
  /// The corners of face prim_ids()[i] at each position i: a leaf's corners in tree order, read
  /// without the indirection into faces() (whose ids may lie anywhere in memory).
  [[nodiscard]] const std::vector<Face>& prim_faces() const { return prim_faces_; }
  /// Node index of the leaf that holds face f.
  [[nodiscard]] int leaf_of_face(int f) const { return leaf_of_face_[f]; }
  /// Index of a node's parent; -1 for the root.
  [[nodiscard]] int parent(int node) const { return parent_[node]; }
  /// Node ranges of each depth: level d is [level_offsets()[d], level_offsets()[d + 1]).
  [[nodiscard]] const std::vector<int>& level_offsets() const { return level_offsets_; }
  [[nodiscard]] int depth() const { return static_cast<int>(level_offsets_.size()) - 1; }
  /// The oriented boundary loop (vertex ids) of a disk node; empty for other nodes.
  [[nodiscard]] std::span<const int> contour(int node) const;
  /// Normal cones of the last refit with cones, one per node (none before the first). A saturated
  /// cone (one that bounds no half-space) has a half-angle of at least pi/2: pi/2 exactly where a
  /// cone function made it (kSaturatedHalfAngle), pi for an internal node above a saturated child.
  /// Test it with NormalCone::saturated(), not by comparing the angle.
  [[nodiscard]] const std::vector<NormalCone>& cones() const { return cones_; }
  /// The faces the tree was built over (shared with the topology, which never changes them);
  /// refits read positions by these ids.
  [[nodiscard]] const std::vector<Face>& faces() const {
    static const std::vector<Face> none;
    return faces_ != nullptr ? *faces_ : none;
  }
  /// Number of vertices of the topology the tree was built from.
  [[nodiscard]] int num_vertices() const { return num_vertices_; }
  /// Sum of the internal nodes' box surface areas over the leaves', at the last refit. A tree
  /// refit to shapes far from the one it was built on has ever looser boxes, and this ratio grows
  /// with them: the cue to rebuild (the simulator rebuilds at 1.5 times its value after a build,
  /// docs/simulator.md 3.6). 1 when every box is flat to a point, infinite when only the
  /// leaves' are.
  [[nodiscard]] double box_area_ratio() const;

  /// Internal nodes whose triangles are edge-connected / are disks, and all internal nodes.
  [[nodiscard]] int num_internal() const;
  [[nodiscard]] int num_connected_internal() const;
  [[nodiscard]] int num_disk_internal() const;
  /// One flag per node: set when a face below it is flagged in `face_flags` (one per face); the
  /// OR of the flags of the faces below it. Costs a pass over `face_flags` and, per flagged face,
  /// the nodes above it not yet flagged: cheap when few faces are (a restricted CCD pass).
  [[nodiscard]] std::vector<std::uint8_t> nodes_holding(
      std::span<const std::uint8_t> face_flags) const;

  /// Swept boxes of every triangle over the linear motion t0 -> t1 and, optionally, CCD cones.
  void refit(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
             const RefitOptions& options);
  /// The same result as refit(v_t0, v_t1, options), bit for bit; after an earlier call of this
  /// one with the same options and no other refit since, it redoes only the nodes above faces
  /// with a vertex whose positions changed. For repeated CCD passes in which a few vertices
  /// change their motion.
  void refit_changed(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
                     const RefitOptions& options);
  /// refit_changed() for a caller that already knows which vertices changed: `moved` flags (one
  /// per vertex) every vertex whose position at t0 or t1 differs from the one this tree's
  /// previous refit used. The result is refit(v_t0, v_t1, options) bit for bit when the flags
  /// are right; a vertex changed but not flagged leaves stale boxes. Empty `moved`, other
  /// options than the previous refit_changed() / refit_moved(), or another refit since, refit
  /// every node. Saves refit_changed()'s copy and comparison of the positions.
  void refit_moved(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
                   const RefitOptions& options, std::span<const std::uint8_t> moved);
  /// Static boxes and skinny (DCD) cones at the positions v.
  void refit(std::span<const Eigen::Vector3d> v, const RefitOptions& options);

 private:
  // The research module's reference refits: the refits below with `optimal` set
  // (src/bvh/optimal_cones.hpp).
  friend struct detail::OptimalCones;
  // The public refits; with `optimal`, every node's cone is the optimal cone of its descendant
  // leaves' normal control directions (exact leaf caps) instead of options.policy's.
  void refit_with(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
                  const RefitOptions& options, bool optimal);
  void refit_changed_with(std::span<const Eigen::Vector3d> v_t0,
                          std::span<const Eigen::Vector3d> v_t1, const RefitOptions& options,
                          bool optimal);
  void refit_moved_with(std::span<const Eigen::Vector3d> v_t0,
                        std::span<const Eigen::Vector3d> v_t1, const RefitOptions& options,
                        std::span<const std::uint8_t> moved, bool optimal);
  void refit_static_with(std::span<const Eigen::Vector3d> v, const RefitOptions& options,
                         bool optimal);
  template <class LeafFn, class PatchFn>
  void refit_levels(const RefitOptions& options, bool optimal, std::span<const std::uint8_t> nodes,
                    int min_count, LeafFn&& leaf, PatchFn&& patch);
  // refit_with(v_t0, v_t1, options, optimal) of the flagged nodes only (all when `nodes` is
  // empty; flags as nodes_holding gives them); the others keep their last refit's box and cone.
  void refit_nodes(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
                   const RefitOptions& options, bool optimal, std::span<const std::uint8_t> nodes);
  // refit_nodes() of the nodes above the flagged vertices (all when `moved` is empty).
  void refit_flagged(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
                     const RefitOptions& options, bool optimal,
                     std::span<const std::uint8_t> moved);
  void forget_changes();
  void compute_flags(const Topology& topology);
  void build_tree(const Topology& topology, std::span<const Eigen::Vector3d> reference,
                  BvhBuild build);

  std::shared_ptr<const std::vector<Face>> faces_;  // Topology::shared_faces(); null: no tree
  int num_vertices_ = 0;
  std::vector<BvhNode> nodes_;
  std::vector<int> prim_ids_;
  // faces_[prim_ids_[i]] for each prim position i: a leaf's corners without the indirection
  // (the refits' leaf loop waits on memory).
  std::vector<Face> prim_faces_;
  std::vector<int> leaf_of_face_;
  std::vector<int> parent_;  // -1 for the root
  std::vector<int> level_offsets_;
  std::vector<int> contour_offsets_;  // CSR per node
  std::vector<int> contour_vertices_;
  std::vector<NormalCone> cones_;
  // Unit Bernstein control directions of each leaf, by prim position (optimal cones only).
  std::vector<Eigen::Vector3d> control_dirs_;
  std::vector<std::uint8_t> degenerate_;
  // What the last refit_changed() fitted (cleared by any other refit), and whether with
  // optimal cones.
  std::optional<RefitOptions> changed_options_;
  bool changed_optimal_ = false;
  std::vector<Eigen::Vector3d> changed_t0_, changed_t1_;
};

}  // namespace clothcd
