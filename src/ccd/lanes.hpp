#pragma once
// Internal: a 3-vector of lanes, T being double or an xsimd batch of doubles, and the vector
// operations the vectorised filters share (np_batch_impl.hpp, face_bounds_impl.hpp), each in the
// scalar code's operation order (Eigen's for Vector3d: dot products left to right, the usual cross
// product). Their includers are compiled without floating-point contraction. Templates only:
// each instruction set instantiates them with its own batch type, so no two sources compiled with
// different target flags share a symbol (the double forms serve the scalar sources alone).

namespace clothcd::ccd_detail::lanes {

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

}  // namespace clothcd::ccd_detail::lanes
