#pragma once
// Internal: the coplanarity cubic in Bernstein form (algorithms.md section 6.1) with a forward
// error bound, the NP filter, and the isolation of the times where it may vanish.
// The triangle is (a, b, c) and the fourth point q: VF uses a, b, c = f0, f1, f2 and q = v;
// EE uses a, b, c = ea0, ea1, eb0 and q = eb1. Both contacts need det(b - a, c - a, q - a) = 0.

#include "ccd/motion.hpp"

namespace clothcd::ccd_detail {

struct BernsteinCubic {
  double k[4];  ///< computed Bernstein coefficients on [0, 1]
  double eta;   ///< |computed - exact| <= eta for every coefficient
};

BernsteinCubic coplanarity_cubic(Kind kind, const Motion& m);

/// True when every coefficient is provably of one sign: no root in [0, 1].
bool np_culls(const BernsteinCubic& c);

/// Time ranges (in increasing order, disjoint) outside of which the exact cubic provably does
/// not vanish, found by de Casteljau subdivision to 2^-depth. Returns the number of ranges, or
/// -1 when there would be more than `cap` of them.
int candidate_times(const BernsteinCubic& c, int depth, double (*ranges)[2], int cap);

}  // namespace clothcd::ccd_detail
