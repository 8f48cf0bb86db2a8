#pragma once
// Internal: the whole-triangle distance bounds of face_bounds.hpp written once for a lane type T,
// either double (face_bounds.cpp) or an xsimd batch of doubles (face_batch_*.cpp). Every
// operation is an IEEE one (+, -, *, /, sqrt), an ordered comparison or a select, in a fixed
// order, and every including source is compiled without floating-point contraction: a lane of a
// batch then computes exactly what the scalar code computes for that pair, bit for bit, whatever
// the input (NaN and infinity included). The orders are Eigen's for Vector3d (lanes.hpp), and
// min / max select as std::min / std::max do.
// Each includer defines FACE_BOUNDS_NAMESPACE, so that code built for different instruction sets
// never shares an inline symbol.

#include <cmath>

#include "core/lanes.hpp"

namespace clothcd::ccd_detail {
namespace FACE_BOUNDS_NAMESPACE {

// The 3-vector of lanes and its operations (lanes.hpp).
template <class T>
using P3 = simd::lanes::Vec3<T>;
using simd::lanes::cross;
using simd::lanes::dot;
using simd::lanes::max_of;
using simd::lanes::min_of;
using simd::lanes::select;
using simd::lanes::sub;

template <class T>
P3<T> min_of(const P3<T>& p, const P3<T>& q) {
  return {min_of(p.x, q.x), min_of(p.y, q.y), min_of(p.z, q.z)};
}
template <class T>
P3<T> max_of(const P3<T>& p, const P3<T>& q) {
  return {max_of(p.x, q.x), max_of(p.y, q.y), max_of(p.z, q.z)};
}

template <class T>
using Tri = P3<T>[3];

// How far b lies wholly on one side of a's plane (0 where it straddles it). The normal is trusted
// as in the feature bounds (proximity.cpp): only where the sine of a's angle at a[0] exceeds 1e-3.
template <class T>
[[gnu::always_inline]] inline T plane_separation(const Tri<T>& a, const Tri<T>& b) {
  using std::sqrt;
  const P3<T> u = sub(a[1], a[0]), v = sub(a[2], a[0]);
  const P3<T> w = cross(u, v);
  const T w2 = dot(w, w);
  const auto trusted = w2 > T(1e-6) * dot(u, u) * dot(v, v);
  T lo(INFINITY), hi(-INFINITY);
  for (int k = 0; k < 3; ++k) {
    const T s = dot(w, sub(b[k], a[0]));
    lo = min_of(lo, s);
    hi = max_of(hi, s);
  }
  const T zero(0.0);
  const T side = select(lo > zero, lo, select(hi < zero, -hi, zero));
  return select(trusted, side / sqrt(w2), zero);
}

// Euclidean gap between the two triangles' boxes (0 where they overlap).
template <class T>
[[gnu::always_inline]] inline T box_gap(const Tri<T>& a, const Tri<T>& b) {
  using std::sqrt;
  P3<T> lo_a = a[0], hi_a = a[0], lo_b = b[0], hi_b = b[0];
  for (int k = 1; k < 3; ++k) {
    lo_a = min_of(lo_a, a[k]);
    hi_a = max_of(hi_a, a[k]);
    lo_b = min_of(lo_b, b[k]);
    hi_b = max_of(hi_b, b[k]);
  }
  const T zero(0.0);
  const P3<T> d = max_of(max_of(sub(lo_b, hi_a), sub(lo_a, hi_b)), P3<T>{zero, zero, zero});
  return sqrt(dot(d, d));
}

// slack.hpp's coordinate_slack of the six corners.
template <class T>
[[gnu::always_inline]] inline T slack(const Tri<T>& a, const Tri<T>& b) {
  using std::abs;
  T m(1.0);
  for (const Tri<T>* t : {&a, &b}) {
    for (int k = 0; k < 3; ++k) {
      const P3<T>& p = (*t)[k];
      m = max_of(m, max_of(max_of(abs(p.x), abs(p.y)), abs(p.z)));
    }
  }
  return T(1e-12) * m;
}

// triangle_triangle_bound given the two triangles' slack.
template <class T>
[[gnu::always_inline]] inline T bound_less(const Tri<T>& a, const Tri<T>& b, const T& slack) {
  const T bound = max_of(max_of(box_gap(a, b), plane_separation(a, b)), plane_separation(b, a));
  return max_of(T(0.0), bound - slack);
}

template <class T>
T triangle_triangle_bound(const Tri<T>& a, const Tri<T>& b) {
  return bound_less(a, b, slack(a, b));
}

// triangles_filter_culls: the verdict, and the bound at t1 in `bound_t1`.
template <class T>
[[gnu::always_inline]] inline auto triangles_filter(const Tri<T>& a_t0, const Tri<T>& a_t1,
                                                    const Tri<T>& b_t0, const Tri<T>& b_t1,
                                                    const T& thickness, T& bound_t1) {
  using std::isfinite;
  using std::sqrt;
  T move2(0.0);
  for (int i = 0; i < 3; ++i) {
    const P3<T> da = sub(a_t1[i], a_t0[i]);
    for (int j = 0; j < 3; ++j) {
      const P3<T> d = sub(da, sub(b_t1[j], b_t0[j]));
      move2 = max_of(move2, dot(d, d));
    }
  }
  // The same test as the distance filter's whole-step bound, with the largest slack of any of
  // the feature pairs (theirs are taken over fewer points).
  const T s0 = slack(a_t0, b_t0), s1 = slack(a_t1, b_t1);
  const T eps = max_of(s0, s1);
  bound_t1 = bound_less(a_t1, b_t1, s1);
  const T bound = T(0.5) * (bound_less(a_t0, b_t0, s0) + bound_t1 - sqrt(move2));
  return isfinite(bound) && bound > thickness + eps;
}

}  // namespace FACE_BOUNDS_NAMESPACE
}  // namespace clothcd::ccd_detail
