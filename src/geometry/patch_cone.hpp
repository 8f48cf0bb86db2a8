#pragma once
// The cone of a whole patch's normals over a linear motion, computed from its triangles at once:
// for a BVH node whose cone is wanted but whose descendants' cones are not.

#include <Eigen/Core>

#include <array>
#include <span>

#include "clothcd/geometry/cone.hpp"

namespace clothcd::detail {

/// A cone holding n(t) / |n(t)| for every t in [0, 1] and every triangle faces[ids[k]] moving
/// linearly from positions v_t0 to v_t1 (ids must not be empty). The axis is the mean of the
/// triangles' unit Bernstein control directions and the half-angle the largest angle from it
/// to any of them, widened by their rounding (the bounds of ccd_leaf_cone): one pass over the
/// triangles and a few transcendental calls in all, against two merges a triangle and one a
/// node for a tree of merges. Saturated when a triangle's normal may vanish during the step or
/// the directions come within about a milliradian of the axis's orthogonal plane.
[[nodiscard]] NormalCone patch_ccd_cone(std::span<const std::array<int, 3>> faces,
                                        std::span<const int> ids,
                                        std::span<const Eigen::Vector3d> v_t0,
                                        std::span<const Eigen::Vector3d> v_t1);

}  // namespace clothcd::detail
