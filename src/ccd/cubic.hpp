#pragma once
// Internal: the coplanarity cubic in Bernstein form (docs/algorithms.md 6.1) with a forward
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

/// The NP filter on the raw (unscaled) points, skipping the rescaling when the coordinate
/// differences are within [2^-300, 2^100] (where the same error bound holds, and the scaled
/// cubic, an exact power-of-two multiple, gives the same answer). `undecided` when out of range
/// or on non-finite input: then use the scaled path.
enum class NpVerdict { Culled, Kept, Undecided };
NpVerdict unscaled_np_filter(Kind kind, const std::array<const Eigen::Vector3d*, 8>& points);

/// True when every coefficient is provably of one sign: no root in [0, 1].
bool np_culls(const BernsteinCubic& c);

/// Bound on |computed - exact| of every Bernstein coefficient obtained from `c` by up to 40
/// levels of de Casteljau halving (`halve`).
double subdivision_error(const BernsteinCubic& c);

/// De Casteljau halving of Bernstein coefficients on [lo, hi] into [lo, mid] and [mid, hi]. T is
/// double or a batch of lanes (np_batch_impl.hpp), with the same operations in the same order.
template <class T>
inline void halve(const T (&b)[4], T (&left)[4], T (&right)[4]) {
  const T half(0.5);
  const T b01 = (b[0] + b[1]) * half, b12 = (b[1] + b[2]) * half, b23 = (b[2] + b[3]) * half;
  const T b012 = (b01 + b12) * half, b123 = (b12 + b23) * half;
  const T mid = (b012 + b123) * half;
  left[0] = b[0];
  left[1] = b01;
  left[2] = b012;
  left[3] = mid;
  right[0] = mid;
  right[1] = b123;
  right[2] = b23;
  right[3] = b[3];
}

/// Every coefficient provably of one sign (error e): the cubic has no root on the range.
/// T is double or a batch of lanes (then the answer is a mask).
template <class T>
inline auto one_sign(const T (&b)[4], const T& e) {
  return (b[0] > e && b[1] > e && b[2] > e && b[3] > e) ||
         (b[0] < -e && b[1] < -e && b[2] < -e && b[3] < -e);
}

/// The values at the two ends (b[0], b[3]) provably of opposite signs: a root on the range.
inline bool sign_change(const double (&b)[4], double e) {
  return (b[0] > e && b[3] < -e) || (b[0] < -e && b[3] > e);
}

}  // namespace clothcd::ccd_detail
