#pragma once
/// @file
/// How an impact zone moves over a substep (docs/simulator.md 3.3). Internal to the simulator.

#include <vector>

#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim::detail {

/// v(x) = v_c + omega x (x - x_c). Applied as x + t v(x) over a substep, the zone's map is
/// linear with determinant 1 + t^2 |omega|^2 > 0, so nothing inside the zone can collide.
struct RigidMotion {
  Vec3 xc = Vec3::Zero(), vc = Vec3::Zero(), omega = Vec3::Zero();
  [[nodiscard]] Vec3 at(const Vec3& x) const { return vc + omega.cross(x - xc); }
};

/// The rigid motion nearest the given point velocities in the weighted least-squares sense: the
/// weighted mean velocity about the weighted centroid, and the angular velocity from the
/// points' angular momentum and inertia (pseudo-inverse: collinear points fix no spin about
/// their line).
[[nodiscard]] RigidMotion fit_rigid(const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                                    const std::vector<double>& w);

}  // namespace clothcd::sim::detail
