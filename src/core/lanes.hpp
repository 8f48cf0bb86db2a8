#pragma once
// Internal: a 3-vector of lanes, T being double or an xsimd batch of doubles, and the vector
// operations the vectorised filters share (np_batch_impl.hpp, face_bounds_impl.hpp,
// distance_batch_impl.hpp), each in the scalar code's operation order (Eigen's for Vector3d: dot
// products left to right, the usual cross product). Their includers are compiled without
// floating-point contraction. Templates only: each instruction set instantiates them with its own
// batch type, so no two sources compiled with different target flags share a symbol (the double
// forms serve the scalar sources alone).

#include <type_traits>

namespace clothcd::simd::lanes {

/// m ? a : b for a scalar; a batch finds its own (xsimd::select) by argument lookup.
template <class T>
std::enable_if_t<std::is_floating_point_v<T>, T> select(bool m, const T& a, const T& b) {
  return m ? a : b;
}
/// std::min(a, b) and std::max(a, b), lane by lane: the same operand on ties and NaN, where
/// xsimd::min and max differ.
template <class T>
T min_of(const T& a, const T& b) {
  return select(b < a, b, a);
}
template <class T>
T max_of(const T& a, const T& b) {
  return select(a < b, b, a);
}

template <class T>
struct Vec3 {
  T x, y, z;
};
template <class T>
Vec3<T> sub(const Vec3<T>& p, const Vec3<T>& q) {
  return {p.x - q.x, p.y - q.y, p.z - q.z};
}
template <class T>
Vec3<T> cross(const Vec3<T>& p, const Vec3<T>& q) {
  return {p.y * q.z - p.z * q.y, p.z * q.x - p.x * q.z, p.x * q.y - p.y * q.x};
}
template <class T>
T dot(const Vec3<T>& p, const Vec3<T>& q) {
  return p.x * q.x + p.y * q.y + p.z * q.z;
}

}  // namespace clothcd::simd::lanes
