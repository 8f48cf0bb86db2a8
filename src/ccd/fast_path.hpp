#pragma once
// Internal: the zero-thickness fast path. A depth-first search over time ranges, earliest first,
// that drops a range when the coplanarity cubic provably has no root on it or the contact point
// is provably outside the features over it, certifies a hit when the cubic provably changes sign
// on it and the contact point is provably inside over all of it, and hands the ranges it cannot
// decide (after a few halvings) to the inclusion solver restricted to that range.

#include <cstdint>

#include "ccd/cubic.hpp"
#include "ccd/inclusion.hpp"

namespace clothcd::ccd_detail {

struct FastOutcome {
  bool hit = false;
  bool certified = false;  ///< decided without the inclusion solver
  double toi = 1, u = 0, v = 0;
  std::uint32_t boxes = 0;  ///< inclusion boxes spent on undecided ranges
};

/// The search examines a range with the inside test from this depth on (shallower ranges are
/// only halved), and at most kFastPathBudget ranges per query (fast_path.cpp says why);
/// fast_path_settle (np_batch.hpp) repeats the search down to a fixed depth.
inline constexpr int kFirstInsideLevel = 2;
inline constexpr int kFastPathBudget = 48;
/// Ranges still undecided at this depth go to the inclusion solver.
inline constexpr int kFastPathMaxLevel = 10;

/// The depth of range whose start the search reports as a certified hit's time of impact: its
/// width is at most toi_tolerance (kMaxRefine = 40 for a tolerance of 0).
int toi_target_level(double toi_tolerance);

/// A certified hit's time of impact: the start of the earliest range of depth `target` (at least
/// `level`) inside [lo, hi] (a range of depth `level` with Bernstein coefficients b and error e,
/// on which the cubic provably changes sign) on which the cubic is not provably of one sign.
double first_root_bound(const double (&b)[4], double lo, double hi, int level, double e,
                        int target);

/// fast_path_solve's search alone, to depth max_level (at most kFastPathMaxLevel): true, with
/// `out` the kernel's outcome (no contact, or a certified hit), where the search ends without
/// the inclusion solver; false where it would call it (a range still undecided at max_level, or
/// the budget spent). `target`: toi_target_level of the kernel's tolerance.
bool fast_path_search(Kind kind, const Motion& m, const BernsteinCubic& c, int target,
                      int max_level, FastOutcome& out);

/// `p` gives the inclusion solver's settings (its time range is ignored); `c` is the query's
/// coplanarity cubic (not NP-culled).
FastOutcome fast_path_solve(Kind kind, const Motion& m, const BernsteinCubic& c,
                            const InclusionParams& p);

}  // namespace clothcd::ccd_detail
