#pragma once
// The strain limiter's 2x2 eigen problem: the principal stretches of a triangle from its Gram
// matrix F^T F, and the cheap test that spares it for triangles within the limits.

#include "clothcd/sim/elements.hpp"

#include <algorithm>
#include <cmath>

namespace clothcd::sim::detail {

// Eigenvalues (descending) of a symmetric 2x2 matrix and the unit eigenvector of the larger.
struct Eig2 {
  double l1, l2;
  Vec2 v1;
};
inline Eig2 eig2(const Mat2& c) {
  const double a = c(0, 0), b = c(0, 1), d = c(1, 1);
  const double half = 0.5 * (a + d);
  const double disc = std::sqrt(0.25 * (a - d) * (a - d) + b * b);
  Eig2 e{half + disc, std::max(0.0, half - disc), Vec2::UnitX()};
  // Of the two expressions of the eigenvector, the longer is the better conditioned.
  const Vec2 p(e.l1 - d, b), q(b, e.l1 - a);
  const Vec2 w = p.squaredNorm() >= q.squaredNorm() ? p : q;
  const double n = w.norm();
  if (n > 0.0) {
    e.v1 = w / n;
  } else if (d > a) {
    e.v1 = Vec2::UnitY();
  }
  return e;
}

// Whether both eigenvalues of the symmetric 2x2 matrix c, as eig2 computes them, are certainly
// within [lo2, hi2] (lo2 = 0: no lower limit), told without the square root and the eigenvector:
// l1 = half + sqrt(q) and l2 = half - sqrt(q) with q the discriminant eig2 takes the root of. The
// bounds keep a margin of 1e-9 relative, far above the few roundings of either form, so where
// this says yes eig2's values are inside too; near a limit, or on NaN, it says no (the caller
// then decides from eig2).
inline bool certainly_within(const Mat2& c, double lo2, double hi2) {
  const double a = c(0, 0), b = c(0, 1), d = c(1, 1);
  const double half = 0.5 * (a + d);
  const double q = 0.25 * (a - d) * (a - d) + b * b;
  const double up = hi2 - half - 1e-9 * hi2;  // how far l1 may exceed half
  if (!(up >= 0.0) || !(q <= up * up)) return false;
  if (lo2 == 0.0) return true;
  const double down = half - lo2 - 1e-9 * half;  // how far l2 may fall below half
  return down >= 0.0 && q <= down * down;
}

}  // namespace clothcd::sim::detail
