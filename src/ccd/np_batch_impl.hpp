#pragma once
// Internal: the body of np_filter_batch for one xsimd architecture, included by one source file
// per instruction set (each compiled with its own target flags and -ffp-contract=off). Every
// lane repeats cubic_of and unscaled_np_filter (cubic.cpp) operation for operation.

#include <xsimd/xsimd.hpp>

#include <cfloat>
#include <cstdint>
#include <limits>

#include "ccd/np_batch.hpp"

namespace clothcd::ccd_detail {
namespace NP_BATCH_NAMESPACE {

template <class Arch>
void np_filter_batch_impl(Kind kind, const NpBatch& b, NpVerdict* verdict) {
  using B = xsimd::batch<double, Arch>;
  using Mask = xsimd::batch_bool<double, Arch>;
  constexpr int W = static_cast<int>(B::size);
  static_assert(NpBatch::kCapacity % W == 0);
  // Point indices of a, b, c, q (as in cubic_of).
  const int ia = kind == Kind::VertexFace ? 1 : 0;
  const int ib = kind == Kind::VertexFace ? 2 : 1;
  const int ic = kind == Kind::VertexFace ? 3 : 2;
  const int iq = kind == Kind::VertexFace ? 0 : 3;
  const B third(3.0);
  const B big(DBL_MAX);
  const B eta_scale(256 * (DBL_EPSILON / 2));
  const B eta_floor(1024 * std::numeric_limits<double>::denorm_min());
  const B low(0x1p-300), high(0x1p100);
  for (int i = 0; i < b.size; i += W) {
    struct V {
      B x, y, z;
    };
    Mask finite(true);
    const auto point = [&](int p) {
      const V v{B::load_unaligned(&b.x[3 * p][i]), B::load_unaligned(&b.x[3 * p + 1][i]),
                B::load_unaligned(&b.x[3 * p + 2][i])};
      finite = finite && (xsimd::abs(v.x) <= big) && (xsimd::abs(v.y) <= big) &&
               (xsimd::abs(v.z) <= big);
      return v;
    };
    const V x0[4] = {point(0), point(1), point(2), point(3)};
    const V x1[4] = {point(4), point(5), point(6), point(7)};
    const auto sub = [](const V& p, const V& q) { return V{p.x - q.x, p.y - q.y, p.z - q.z}; };
    const auto cross = [](const V& p, const V& q) {
      return V{p.y * q.z - p.z * q.y, p.z * q.x - p.x * q.z, p.x * q.y - p.y * q.x};
    };
    const auto dot = [](const V& p, const V& q) { return p.x * q.x + p.y * q.y + p.z * q.z; };
    const auto max_abs = [](const V& p) {
      return xsimd::max(xsimd::max(xsimd::abs(p.x), xsimd::abs(p.y)), xsimd::abs(p.z));
    };
    const V e1_0 = sub(x0[ib], x0[ia]), e2_0 = sub(x0[ic], x0[ia]);
    const V r0 = sub(x0[iq], x0[ia]);
    const V e1_1 = sub(x1[ib], x1[ia]), e2_1 = sub(x1[ic], x1[ia]);
    const V r1 = sub(x1[iq], x1[ia]);
    const V n0 = cross(e1_0, e2_0), n1 = cross(e1_1, e2_1);
    const V c01 = cross(e1_0, e2_1), c10 = cross(e1_1, e2_0);
    const V nx2 = {c01.x + c10.x, c01.y + c10.y, c01.z + c10.z};
    const B k0 = dot(n0, r0);
    const B k1 = (dot(nx2, r0) + dot(n0, r1)) / third;
    const B k2 = (dot(nx2, r1) + dot(n1, r0)) / third;
    const B k3 = dot(n1, r1);
    // The maximum is exact whatever the order (finite lanes; the others are undecided).
    const B a = xsimd::max(xsimd::max(xsimd::max(max_abs(e1_0), max_abs(e2_0)),
                                      xsimd::max(max_abs(r0), max_abs(e1_1))),
                           xsimd::max(max_abs(e2_1), max_abs(r1)));
    const B e = eta_scale * (a * a * a) + eta_floor;
    const Mask decided = finite && (a >= low) && (a <= high);
    const Mask culled = ((k0 > e) && (k1 > e) && (k2 > e) && (k3 > e)) ||
                        ((k0 < -e) && (k1 < -e) && (k2 < -e) && (k3 < -e));
    bool d[W], c[W];
    decided.store_unaligned(d);
    culled.store_unaligned(c);
    const int n = b.size - i < W ? b.size - i : W;
    for (int l = 0; l < n; ++l) {
      verdict[i + l] = !d[l] ? NpVerdict::Undecided : (c[l] ? NpVerdict::Culled : NpVerdict::Kept);
    }
  }
}

}  // namespace NP_BATCH_NAMESPACE
}  // namespace clothcd::ccd_detail
