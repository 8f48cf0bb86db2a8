#pragma once
// Validation of the DetectOptions both detectors share, at their public boundary.

#include <fmt/format.h>

#include <cmath>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/types.hpp"

namespace clothcd::detail {

/// Throws InputError naming the option when the thickness or the toi tolerance is negative, NaN
/// or infinite. Left to the kernels, a NaN thickness made every box NaN, so that no box overlapped
/// and a step silently reported no collision, or threw std::invalid_argument from the first
/// kernel a pair did reach.
inline void check_common_options(const DetectOptions& o) {
  if (!(o.thickness >= 0) || !std::isfinite(o.thickness)) {
    throw InputError(fmt::format("thickness must be finite and >= 0, got {}", o.thickness));
  }
  if (!(o.toi_tolerance >= 0) || !std::isfinite(o.toi_tolerance)) {
    throw InputError(fmt::format("toi tolerance must be finite and >= 0, got {}", o.toi_tolerance));
  }
}

}  // namespace clothcd::detail
