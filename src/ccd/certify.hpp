#pragma once
// Internal: the "inside" half of the fast path. A zero-thickness contact is a time where the four
// points are coplanar (a root of the coplanarity cubic) AND the contact point lies in the
// features. For a time range, these functions are evaluated in midpoint-radius interval
// arithmetic with a forward error bound (docs/ccd.md), so each answer is certain:
//   VF (triangle a b c, point q, n = (b - a) x (c - a)): n . ((b - a) x (q - a)),
//     n . ((c - b) x (q - b)) and n . ((q - a) x (c - a)), equal to |n|^2 times the barycentric
//     weights of c, a and b of q's projection onto the plane;
//   EE (edges a0 a1, b0 b1, ea = a1 - a0, eb = b1 - b0, n = ea x eb, d = b0 - a0): u |n|^2 =
//     n . (d x eb), (1 - u) |n|^2 = n . ((a1 - b0) x eb), v |n|^2 = n . (d x ea) and
//     (1 - v) |n|^2 = n . ((a0 - b1) x ea), u and v the crossing parameters of the projections.
// All of them > 0 over the range: any coplanar time in it is a contact. One of them < 0 over the
// whole range: no coplanar time in it is a contact (the projection is outside, n != 0).

#include "ccd/motion.hpp"

namespace clothcd::ccd_detail {

/// The difference vectors the inside functions use, at t = 0 and t = 1 (each one rounding of the
/// scaled inputs), and the largest |component| of all of them.
struct InsideData {
  Kind kind;
  double x0[5][3], x1[5][3];
  double a_max;
};

InsideData inside_data(Kind kind, const Motion& m);

enum class Inside { No, Yes, Unknown };

/// Certain answer over t in [lo, hi] (dyadic bounds in [0, 1]) when it can be decided; unless the
/// answer is No, `u`, `v` receive the contact parameters at the range's middle (VF: weights of f1
/// and f2; EE: positions along edge a and edge b), meaningful for Yes.
Inside inside_over(const InsideData& d, double lo, double hi, double& u, double& v);

}  // namespace clothcd::ccd_detail
