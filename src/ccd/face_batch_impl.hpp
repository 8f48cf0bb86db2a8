#pragma once
// Internal: the body of triangles_filter_batch for one xsimd architecture, included by one
// source file per instruction set (each compiled with its own target flags and
// -ffp-contract=off, and its own FACE_BOUNDS_NAMESPACE).

#include <xsimd/xsimd.hpp>

#include <algorithm>

#include "ccd/face_batch.hpp"
#include "ccd/face_bounds_impl.hpp"

namespace clothcd::ccd_detail::FACE_BOUNDS_NAMESPACE {

// Point p of the entries i..i + B::size - 1 of a batch.
template <class B, int Triangles>
P3<B> load(const TriangleBatch<Triangles>& b, int p, int i) {
  return {B::load_aligned(&b.x[3 * p][i]), B::load_aligned(&b.x[3 * p + 1][i]),
          B::load_aligned(&b.x[3 * p + 2][i])};
}

template <class Arch>
void triangles_filter_batch_impl(const FacePairBatch& b, double thickness, bool* culls,
                                 double* bound_t1) {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = static_cast<int>(B::size);
  static_assert(FacePairBatch::kCapacity % W == 0);
  const B th(thickness);
  for (int i = 0; i < b.size; i += W) {
    const auto point = [&](int p) { return load<B>(b, p, i); };
    const Tri<B> a0 = {point(0), point(1), point(2)};
    const Tri<B> a1 = {point(3), point(4), point(5)};
    const Tri<B> b0 = {point(6), point(7), point(8)};
    const Tri<B> b1 = {point(9), point(10), point(11)};
    B d1(0.0);
    const auto culled = triangles_filter(a0, a1, b0, b1, th, d1);
    bool c[W];
    alignas(64) double d[W];
    culled.store_unaligned(c);
    d1.store_aligned(d);
    const int n = std::min(W, b.size - i);
    std::copy(c, c + n, culls + i);
    std::copy(d, d + n, bound_t1 + i);
  }
}

template <class Arch>
void triangle_bound_batch_impl(const StaticFacePairBatch& b, double* bound) {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = static_cast<int>(B::size);
  static_assert(StaticFacePairBatch::kCapacity % W == 0);
  for (int i = 0; i < b.size; i += W) {
    const auto point = [&](int p) { return load<B>(b, p, i); };
    const Tri<B> ta = {point(0), point(1), point(2)};
    const Tri<B> tb = {point(3), point(4), point(5)};
    alignas(64) double d[W];
    triangle_triangle_bound(ta, tb).store_aligned(d);
    std::copy(d, d + std::min(W, b.size - i), bound + i);
  }
}

}  // namespace clothcd::ccd_detail::FACE_BOUNDS_NAMESPACE
