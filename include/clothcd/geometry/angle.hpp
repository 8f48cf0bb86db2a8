#pragma once
/// @file
/// Angles between directions, accurate at every scale.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace clothcd {

/// u x v computed as u x (v - u): the same vector, but for nearly parallel unit vectors the
/// difference is exact (Sterbenz), so the result keeps full relative precision where the direct
/// form loses it (absolute error ~1e-16 on a vector of length ~angle).
[[nodiscard]] inline Eigen::Vector3d precise_cross(const Eigen::Vector3d& u,
                                                   const Eigen::Vector3d& v) {
  return u.cross(v - u);
}

/// The angle in [0, pi] between two non-zero vectors of similar length (unit directions).
/// atan2(|u x v|, u.v) keeps full relative precision for tiny angles, where acos(u.v) cannot
/// resolve anything below about 1e-8 rad.
[[nodiscard]] inline double angle_between(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  return std::atan2(precise_cross(u, v).norm(), u.dot(v));
}

}  // namespace clothcd
