#pragma once
// Argument checks shared by the cone kernels: NaN or infinite input is a contract violation and
// throws std::invalid_argument naming the function and the argument.

#include <fmt/format.h>

#include <Eigen/Core>
#include <cmath>
#include <stdexcept>

namespace clothcd::detail {

inline void require_finite(const Eigen::Vector3d& v, const char* function, const char* what) {
  if (!v.allFinite()) {
    throw std::invalid_argument(fmt::format("{}: {} must be finite, got ({}, {}, {})", function,
                                            what, v.x(), v.y(), v.z()));
  }
}

inline void require_finite_angle(double angle, const char* function, const char* what) {
  if (!std::isfinite(angle) || angle < 0.0) {
    throw std::invalid_argument(
        fmt::format("{}: {} must be a finite non-negative angle, got {}", function, what, angle));
  }
}

}  // namespace clothcd::detail
