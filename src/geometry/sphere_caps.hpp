#pragma once
// Caps on the unit sphere through one, two or three directions: the building blocks of the
// exact leaf cone and of the optimal cone (Welzl on the sphere). Internal to the geometry module.

#include <Eigen/Core>

#include "clothcd/geometry/cone.hpp"

namespace clothcd::detail {

/// The unit tangent at unit `p` pointing along the great circle toward `q`, or zero when `q` is
/// (anti)parallel to `p`. Computed as (p x q) x p, which ignores the length of p and q.
[[nodiscard]] Eigen::Vector3d tangent_toward(const Eigen::Vector3d& p, const Eigen::Vector3d& q);

/// The point at angle `alpha` from unit `p` along the unit tangent `w`, renormalized.
[[nodiscard]] Eigen::Vector3d rotate_toward(const Eigen::Vector3d& p, const Eigen::Vector3d& w,
                                            double alpha);

/// The smallest cap with unit directions `p` and `q` on its rim (the diametral cap).
/// Saturated when they are antiparallel. No slack added.
[[nodiscard]] NormalCone diametral_cap(const Eigen::Vector3d& p, const Eigen::Vector3d& q);

/// The cap below pi/2 with unit directions `p`, `q`, `r` on its rim, found in the stereographic
/// plane at a point near its centre (insensitive to the rounding of |p| = 1, unlike the plane
/// through the three tips, and well conditioned up to pi/2).
/// Saturated when no such cap exists (the three lie on a great circle). No slack added.
[[nodiscard]] NormalCone circumcap(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                   const Eigen::Vector3d& r);

/// The largest angle from unit `axis` to the given directions, or pi/2 (saturated) when one lies
/// on or behind the equator of `axis`.
[[nodiscard]] double max_angle_from(const Eigen::Vector3d& axis, const Eigen::Vector3d* dirs,
                                    std::size_t count);

/// The minimal cap containing two or three unit directions (`r` may be null): the best of the
/// diametral caps that contain the rest, else the circumcap. The half-angle is the largest angle
/// from the chosen axis to the inputs, so containment of the inputs holds by construction.
[[nodiscard]] NormalCone minimal_cap(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                     const Eigen::Vector3d* r);

}  // namespace clothcd::detail
