#pragma once
/// @file
/// Normal cones and their algebra: the merges of Provot (PROVOT) and of Han et al. 2021
/// (PROPOSED), the CCD leaf cones, and the optimal cone of a vector set (Barequet-Elber).
/// See docs/algorithms.md (shared) sections 3 and 4 for the formulas and the paper's errata.

#include <Eigen/Core>
#include <span>

namespace clothcd {

/// A cone of directions with unit `axis` and `half_angle` (the paper's spread angle) in radians.
struct NormalCone {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double half_angle = 0.0;

  /// A saturated cone (half-angle >= pi/2) bounds no half-space, so it can cull nothing.
  [[nodiscard]] bool saturated() const;
};

/// Provot's merge (the paper's eq. 1-3): axis = unitize(a1 + a2), angle = beta/2 + max(t1, t2).
[[nodiscard]] NormalCone merge_provot(const NormalCone& a, const NormalCone& b);

/// The paper's M_Proposed (eq. 7-8): the exact minimal cone enclosing both cones.
[[nodiscard]] NormalCone merge_tight(const NormalCone& a, const NormalCone& b);

/// How a leaf cone bounds a triangle's normal over a linear motion.
enum class LeafConePolicy {
  Tang,      ///< C_Tang: Provot merges of the three Bernstein control directions (PROVOT).
  Proposed,  ///< C_Proposed: the same nesting with tight merges (PROPOSED).
  Exact,     ///< The minimal cap of the three control directions (ours).
};

/// A cone containing the normal of triangle (a, b, c) at every time of the linear motion from
/// t0 to t1. Saturated when the triangle degenerates during the step.
[[nodiscard]] NormalCone ccd_leaf_cone(const Eigen::Vector3d& a_t0, const Eigen::Vector3d& b_t0,
                                       const Eigen::Vector3d& c_t0, const Eigen::Vector3d& a_t1,
                                       const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1,
                                       LeafConePolicy policy);

/// The skinny cone of a static triangle (discrete collision detection).
[[nodiscard]] NormalCone dcd_leaf_cone(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c);

/// The minimal cone enclosing the given unit vectors (expected linear time, via the minimum
/// enclosing ball of the tips). Saturated when no cone below pi/2 exists.
[[nodiscard]] NormalCone optimal_cone(std::span<const Eigen::Vector3d> unit_vectors);

}  // namespace clothcd
