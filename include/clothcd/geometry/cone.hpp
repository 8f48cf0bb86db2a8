#pragma once
/// @file
/// Normal cones and their algebra: the merges of Provot (PROVOT) and of Han et al. 2021
/// (PROPOSED), the CCD leaf cones, and the optimal cone of a vector set (Barequet-Elber).
/// See docs/algorithms.md sections 3 and 4 for the formulas and the paper's errata, and
/// docs/cones.md for the numerical choices made here.
///
/// Conventions shared by every function below:
/// - A saturated result (half-angle >= pi/2) is returned as exactly `kSaturatedHalfAngle` with a
///   finite unit axis, so statistics over cones never see NaN.
/// - Results are inflated by `kConeSlack` so that containment survives rounding.
/// - NaN or infinite input throws std::invalid_argument; degenerate input (zero vectors,
///   zero-area triangles, antiparallel axes) gives a saturated cone.

#include <Eigen/Core>
#include <numbers>
#include <span>

namespace clothcd {

/// The half-angle stored in every saturated cone (the paper's convention).
inline constexpr double kSaturatedHalfAngle = std::numbers::pi / 2;
/// Inflation (radians) added to computed cones so containment holds under rounding.
inline constexpr double kConeSlack = 1e-12;

/// A cone of directions with unit `axis` and `half_angle` (the paper's spread angle) in radians.
struct NormalCone {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double half_angle = 0.0;

  /// A saturated cone (half-angle >= pi/2) bounds no half-space, so it can cull nothing.
  [[nodiscard]] bool saturated() const;
};

/// The saturated cone (it stands for "every direction").
[[nodiscard]] inline NormalCone saturated_cone(
    const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ()) {
  return {axis, kSaturatedHalfAngle};
}

/// Provot's merge (the paper's eq. 1-3): axis = unitize(a1 + a2), angle = beta/2 + max(t1, t2).
[[nodiscard]] NormalCone merge_provot(const NormalCone& a, const NormalCone& b);

/// The paper's M_Proposed (eq. 7-8): the exact minimal cone enclosing both cones.
[[nodiscard]] NormalCone merge_tight(const NormalCone& a, const NormalCone& b);

/// Which binary merge an internal node uses.
enum class ConeMerge {
  Provot,  ///< merge_provot (the paper's PROVOT configuration).
  Tight,   ///< merge_tight (the paper's PROPOSED configuration).
};

/// merge_provot or merge_tight, chosen at run time.
[[nodiscard]] inline NormalCone merge_cones(const NormalCone& a, const NormalCone& b,
                                            ConeMerge merge) {
  return merge == ConeMerge::Provot ? merge_provot(a, b) : merge_tight(a, b);
}

/// True when the direction of `dir` lies in `cone` (always for a saturated cone). A zero `dir`
/// has no direction: only a saturated cone contains it.
[[nodiscard]] bool contains(const NormalCone& cone, const Eigen::Vector3d& dir);

/// True when `outer` contains every direction of `inner` (up to `slack` radians).
[[nodiscard]] bool contains(const NormalCone& outer, const NormalCone& inner, double slack = 0.0);

/// How a leaf cone bounds a triangle's normal over a linear motion.
enum class LeafConePolicy {
  Tang,      ///< C_Tang: Provot merges of the three Bernstein control directions (PROVOT).
  Proposed,  ///< C_Proposed: the same nesting with tight merges (PROPOSED).
  Exact,     ///< The minimal cap of the three control directions (ours).
};

/// The unnormalized normal of a linearly moving triangle is the quadratic Bernstein polynomial
/// n(t) = (1-t)^2 n0 + 2t(1-t) nx + t^2 n1. Every n(t) is a non-negative combination of the
/// three control vectors, which is why a cap (< pi/2) containing their directions bounds n(t).
struct BernsteinNormal {
  Eigen::Vector3d n0;  ///< (b0 - a0) x (c0 - a0): the normal at t = 0, unnormalized.
  Eigen::Vector3d nx;  ///< 0.5 [(b0 - a0) x (c1 - a1) + (b1 - a1) x (c0 - a0)].
  Eigen::Vector3d n1;  ///< (b1 - a1) x (c1 - a1): the normal at t = 1, unnormalized.

  /// n(t), unnormalized.
  [[nodiscard]] Eigen::Vector3d at(double t) const {
    const double s = 1.0 - t;
    return s * s * n0 + 2.0 * t * s * nx + t * t * n1;
  }
};

/// The control vectors of the normal of triangle (a, b, c) moving linearly from t0 to t1.
[[nodiscard]] BernsteinNormal bernstein_normal(
    const Eigen::Vector3d& a_t0, const Eigen::Vector3d& b_t0, const Eigen::Vector3d& c_t0,
    const Eigen::Vector3d& a_t1, const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1);

/// A cone containing the normal of triangle (a, b, c) at every time of the linear motion from
/// t0 to t1. Saturated when the triangle degenerates during the step.
[[nodiscard]] NormalCone ccd_leaf_cone(const Eigen::Vector3d& a_t0, const Eigen::Vector3d& b_t0,
                                       const Eigen::Vector3d& c_t0, const Eigen::Vector3d& a_t1,
                                       const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1,
                                       LeafConePolicy policy);

/// The skinny cone of a static triangle (discrete collision detection).
[[nodiscard]] NormalCone dcd_leaf_cone(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c);

/// The minimal cone enclosing the given unit vectors, in expected linear time (a randomized
/// incremental search on the sphere, seeded by the set's size: the same input always gives the
/// same cone). Saturated when no cone below pi/2 exists, i.e. when no open hemisphere holds the
/// set. The half-angle is the largest angle from the axis to any input plus `kConeSlack`, so
/// every input is contained; it exceeds the minimum by at most ~1e-12 of it (rounding).
/// Vectors need not be exactly unit (only directions matter); a zero vector saturates; an empty
/// span throws std::invalid_argument.
[[nodiscard]] NormalCone optimal_cone(std::span<const Eigen::Vector3d> unit_vectors);

/// A run of consecutive vectors of a set together with a cone believed to enclose them (e.g. a
/// tree node's child and its optimal cone).
struct ConePart {
  std::size_t count = 0;
  NormalCone cone;
};

/// optimal_cone(unit_vectors) for a set split into consecutive `parts` (their counts must add up
/// to the set's size, else std::invalid_argument): each part's three vectors farthest from its
/// cone's axis are tried first, which saves most of the search when the cones are optimal. The
/// parts only order the search: whatever their cones, the result is the minimal cone (up to
/// rounding) and contains every vector.
[[nodiscard]] NormalCone optimal_cone(std::span<const Eigen::Vector3d> unit_vectors,
                                      std::span<const ConePart> parts);

}  // namespace clothcd
