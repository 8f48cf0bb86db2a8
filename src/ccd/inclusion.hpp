#pragma once
// Internal: the conservative inclusion solver (docs/algorithms.md 5.2, written from the
// description). F(t, u, v) is the vector between the two closest-point candidates:
//   VF: F = p - (a + u (b - a) + v (c - a)),  u, v >= 0, u + v <= 1
//   EE: F = (a + u (b - a)) - (c + v (d - c)),  u, v in [0, 1]
// with every point moving linearly in t. F is affine in each parameter, so over a box each
// coordinate of F lies between the smallest and largest of its 8 corner values.

#include <cstdint>

#include "ccd/motion.hpp"

namespace clothcd::ccd_detail {

struct InclusionParams {
  double t_lo = 0, t_hi = 1;  ///< the time range searched (dyadic bounds)
  double thickness = 0;       ///< scaled
  double tolerance = 0;       ///< scaled absolute width of F below which a box counts as a hit
  double toi_tolerance = 0;   ///< the reported time of impact may be this much early
  std::uint32_t max_boxes = 1u << 16;
};

struct InclusionOutcome {
  bool hit = false;
  double toi = 1;  ///< lower time bound of the earliest box that could not be rejected
  double u = 0, v = 0;
  std::uint32_t boxes = 0;
};

/// Rounding error bound of one computed corner value of F on an axis whose coordinates are at
/// most `max_abs` in magnitude (derivation in docs/ccd.md: at most 51 u max_abs, plus underflow).
double corner_error_bound(double max_abs);

InclusionOutcome inclusion_solve(Kind kind, const Motion& m, const InclusionParams& p);

}  // namespace clothcd::ccd_detail
