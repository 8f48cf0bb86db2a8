#pragma once
// Internal: the per-triangle part of patch_ccd_cone (patch_block.hpp) written once for a lane
// type T, double or an xsimd batch of doubles, in one operation order (Eigen's for Vector3d,
// core/lanes.hpp); every includer is compiled without floating-point contraction, so every body
// computes the same bits for a triangle. Each includer defines PATCH_CONTROLS_NAMESPACE, so that
// code built for different instruction sets never shares an inline symbol.

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include "core/lanes.hpp"
#include "geometry/patch_block.hpp"

namespace clothcd::detail {
namespace PATCH_CONTROLS_NAMESPACE {

using simd::lanes::cross;
using simd::lanes::dot;
using simd::lanes::select;
using simd::lanes::sub;
template <class T>
using P3 = simd::lanes::Vec3<T>;

// One triangle's (or lane's) Bernstein control vectors, their squared lengths, their unit
// directions and the squared error ratios of ccd_leaf_cone's bounds.
template <class T>
struct PatchControls {
  P3<T> n[3], unit[3];
  T q[3];
  T r0, r1, rx;
  T in_range;  // 1 where every squared norm lies within the bounds' range, else 0
};

template <class T>
[[gnu::always_inline]] inline PatchControls<T> patch_controls(const P3<T> (&x0)[3],
                                                              const P3<T> (&x1)[3]) {
  using std::sqrt;
  constexpr double u = std::numeric_limits<double>::epsilon() / 2;
  constexpr double u2 = u * u;
  const P3<T> e10 = sub(x0[1], x0[0]), e20 = sub(x0[2], x0[0]);
  const P3<T> e11 = sub(x1[1], x1[0]), e21 = sub(x1[2], x1[0]);
  PatchControls<T> c;
  c.n[0] = cross(e10, e20);
  const P3<T> m = cross(e10, e21), k = cross(e11, e20);
  const T half(0.5);
  c.n[1] = {half * (m.x + k.x), half * (m.y + k.y), half * (m.z + k.z)};
  c.n[2] = cross(e11, e21);
  const T s10 = dot(e10, e10), s20 = dot(e20, e20), s11 = dot(e11, e11), s21 = dot(e21, e21);
  for (int i = 0; i < 3; ++i)
    c.q[i] = dot(c.n[i], c.n[i]);
  const T lo(1e-140), hi(1e140);
  auto in = [&](const T& x) { return (x >= lo) & (x <= hi); };
  auto ok = in(s10);
  for (const T& x : {s20, s11, s21, c.q[0], c.q[1], c.q[2]})
    ok = ok & in(x);
  c.in_range = select(ok, T(1.0), T(0.0));
  const T k256(256 * u2);
  c.r0 = k256 * (s10 * s20) / c.q[0];
  c.r1 = k256 * (s11 * s21) / c.q[2];
  c.rx = k256 * (s10 * s21 + s11 * s20) / c.q[1] + T(8 * u2);
  for (int i = 0; i < 3; ++i) {
    const T len = sqrt(c.q[i]);
    c.unit[i] = {c.n[i].x / len, c.n[i].y / len, c.n[i].z / len};
  }
  return c;
}

// Gathers faces[ids[0, count)] (count in [1, 8]; the last repeats into the unused lanes) and
// computes their controls with batches of B::size lanes (B double: one at a time).
template <class B>
void patch_block(const std::array<int, 3>* faces, const int* ids, int count,
                 const Eigen::Vector3d* v0, const Eigen::Vector3d* v1, PatchBlock& out) {
  constexpr int L = PatchBlock::kLanes;
  alignas(64) double x[18][L];
  for (int l = 0; l < L; ++l) {
    const std::array<int, 3>& t = faces[ids[l < count ? l : count - 1]];
    for (int j = 0; j < 3; ++j) {
      for (int d = 0; d < 3; ++d) {
        x[3 * j + d][l] = v0[t[j]][d];
        x[9 + 3 * j + d][l] = v1[t[j]][d];
      }
    }
  }
  constexpr int W = [] {
    if constexpr (std::is_floating_point_v<B>) {
      return 1;
    } else {
      return static_cast<int>(B::size);
    }
  }();
  auto load = [](const double* p) {
    if constexpr (std::is_floating_point_v<B>) {
      return *p;
    } else {
      return B::load_aligned(p);
    }
  };
  auto store = [](double* p, const B& v) {
    if constexpr (std::is_floating_point_v<B>) {
      *p = v;
    } else {
      v.store_aligned(p);
    }
  };
  for (int l = 0; l < L; l += W) {
    P3<B> p0[3], p1[3];
    for (int j = 0; j < 3; ++j) {
      p0[j] = {load(&x[3 * j][l]), load(&x[3 * j + 1][l]), load(&x[3 * j + 2][l])};
      p1[j] = {load(&x[9 + 3 * j][l]), load(&x[9 + 3 * j + 1][l]), load(&x[9 + 3 * j + 2][l])};
    }
    const PatchControls<B> c = patch_controls(p0, p1);
    for (int i = 0; i < 3; ++i) {
      store(&out.n[i][0][l], c.n[i].x);
      store(&out.n[i][1][l], c.n[i].y);
      store(&out.n[i][2][l], c.n[i].z);
      store(&out.unit[i][0][l], c.unit[i].x);
      store(&out.unit[i][1][l], c.unit[i].y);
      store(&out.unit[i][2][l], c.unit[i].z);
      store(&out.q[i][l], c.q[i]);
    }
    store(&out.r0[l], c.r0);
    store(&out.r1[l], c.r1);
    store(&out.rx[l], c.rx);
    store(&out.in_range[l], c.in_range);
  }
}

}  // namespace PATCH_CONTROLS_NAMESPACE
}  // namespace clothcd::detail
