#pragma once
/// @file
/// How an impact zone moves over a substep (docs/simulator.md 3.3). Internal to the simulator.

#include <optional>
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

/// v(x) = v_c + A (x - x_c). Over a substep of length h the zone's map is x -> x + t h v(x),
/// t in [0, 1]; with |h A|_2 < 1 it stays invertible, so nothing inside the zone can collide,
/// and gaps inside it shrink by at most that factor.
struct AffineMotion {
  Vec3 xc = Vec3::Zero(), vc = Vec3::Zero();
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  [[nodiscard]] Vec3 at(const Vec3& x) const { return vc + a * (x - xc); }
};

/// Limits under which `fit_affine` gives a motion.
struct AffineLimits {
  /// Largest |h A|_2 (spectral norm) over the substep.
  double max_strain = 0.2;
  /// Smallest ratio of the points' least to greatest principal spread (standard deviation):
  /// flatter point sets fix the velocity's gradient across them from noise.
  double min_flatness = 0.01;
};

/// The affine motion nearest the given point velocities in the weighted least-squares sense
/// (weighted centroid and mean velocity, A = sum w (v - v_c) d^T (sum w d d^T)^-1), or nothing
/// when the points are too flat or the motion strains more than the limits allow over a
/// substep of length `h`.
[[nodiscard]] std::optional<AffineMotion> fit_affine(const std::vector<Vec3>& x,
                                                     const std::vector<Vec3>& v,
                                                     const std::vector<double>& w, double h,
                                                     const AffineLimits& limits = {});

}  // namespace clothcd::sim::detail
