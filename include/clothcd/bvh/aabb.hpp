#pragma once
/// @file
/// Axis-aligned boxes and the operations the library's boxes share: closed-box overlap and
/// outward rounding. Node boxes are double, BvhNode::lo and hi, grown and tested by the same
/// inflate and overlap; feature boxes, of the vertices, edges and faces in the narrow phase, are
/// float (half the memory traffic of its box tests), rounded outwards so that each still contains
/// the double box it came from. Rounding outwards keeps every box test conservative: two boxes
/// overlap whenever the exact boxes do.

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <initializer_list>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "clothcd/core/ulp.hpp"

namespace clothcd {

/// A closed box [lo, hi] in 3-D.
template <class T>
struct Aabb {
  std::array<T, 3> lo{}, hi{};
  bool operator==(const Aabb&) const = default;
};

/// A feature's swept box, in float, rounded outwards (swept_feature_box).
using FeatureBox = Aabb<float>;

/// Whether the closed boxes [alo, ahi] and [blo, bhi] overlap (touching counts). Evaluated
/// without short-circuit: one branch per test instead of up to six badly predicted ones.
template <class V>
[[nodiscard]] inline bool overlap(const V& alo, const V& ahi, const V& blo, const V& bhi) {
  const int hit = int(alo[0] <= bhi[0]) & int(alo[1] <= bhi[1]) & int(alo[2] <= bhi[2]) &
                  int(blo[0] <= ahi[0]) & int(blo[1] <= ahi[1]) & int(blo[2] <= ahi[2]);
  return hit != 0;
}
template <class T>
[[nodiscard]] inline bool overlap(const Aabb<T>& a, const Aabb<T>& b) {
  return overlap(a.lo, a.hi, b.lo, b.hi);
}
/// The same test for feature boxes, the narrow phase's most frequent one: on x86-64 its six
/// comparisons as two SSE comparisons of three lanes (the same float comparisons, so the same
/// answers, NaN included), half the instructions of the scalar form.
[[nodiscard]] inline bool overlap(const FeatureBox& a, const FeatureBox& b) {
#if defined(__SSE2__)
  static_assert(sizeof(FeatureBox) == 6 * sizeof(float) &&
                offsetof(FeatureBox, hi) == 3 * sizeof(float));
  const auto* fa = reinterpret_cast<const float*>(&a);
  const auto* fb = reinterpret_cast<const float*>(&b);
  // Lanes lo0 lo1 lo2 (hi0), and hi0 hi1 hi2 (hi2) shuffled from the four floats at offset 2.
  const __m128 alo = _mm_loadu_ps(fa), blo = _mm_loadu_ps(fb);
  const __m128 a2 = _mm_loadu_ps(fa + 2), b2 = _mm_loadu_ps(fb + 2);
  const __m128 ahi = _mm_shuffle_ps(a2, a2, _MM_SHUFFLE(3, 3, 2, 1));
  const __m128 bhi = _mm_shuffle_ps(b2, b2, _MM_SHUFFLE(3, 3, 2, 1));
  const __m128 both = _mm_and_ps(_mm_cmple_ps(alo, bhi), _mm_cmple_ps(blo, ahi));
  return (_mm_movemask_ps(both) & 7) == 7;
#else
  return overlap(a.lo, a.hi, b.lo, b.hi);
#endif
}

/// Grows the double box [lo, hi] by `margin` on every side, rounded outwards (one ulp past the
/// rounded sum, so it contains the exact grown box); nothing for margin <= 0.
template <class V>
inline void inflate(V& lo, V& hi, double margin) {
  if (margin <= 0) return;
  for (int k = 0; k < 3; ++k) {
    lo[k] = detail::next_down(lo[k] - margin);
    hi[k] = detail::next_up(hi[k] + margin);
  }
}

namespace detail {
/// The largest float at most x / the smallest at least x.
[[nodiscard]] inline float round_down(double x) {
  const float f = static_cast<float>(x);
  return f > x ? next_down(f) : f;
}
[[nodiscard]] inline float round_up(double x) {
  const float f = static_cast<float>(x);
  return f < x ? next_up(f) : f;
}
}  // namespace detail

/// The smallest float box containing the double box [lo, hi].
template <class V>
[[nodiscard]] inline FeatureBox to_feature_box(const V& lo, const V& hi) {
  FeatureBox b;
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = detail::round_down(lo[k]);
    b.hi[k] = detail::round_up(hi[k]);
  }
  return b;
}

/// The box of the points grown by `margin` (inflate), as a float box: the narrow phase's box of
/// a feature over a step, from its vertices' positions at both ends.
[[nodiscard]] inline FeatureBox swept_feature_box(std::initializer_list<const Eigen::Vector3d*> pts,
                                                  double margin) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Eigen::Vector3d* p : pts) {
    lo = lo.cwiseMin(*p);
    hi = hi.cwiseMax(*p);
  }
  inflate(lo, hi, margin);
  return to_feature_box(lo, hi);
}

}  // namespace clothcd
