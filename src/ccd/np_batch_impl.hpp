#pragma once
// Internal: the vector NP filter, instantiated once per instruction set (np_batch_<isa>.cpp, each
// compiled for its own target) and selected at run time (np_batch.cpp). The operation order
// follows cubic_of and unscaled_np_filter in cubic.cpp exactly (see np_batch.hpp).

#include <xsimd/xsimd.hpp>

#include <cfloat>

#include "ccd/np_block.hpp"

namespace clothcd::ccd_detail {

struct NpBlockKernel {
  template <class Arch>
  void operator()(Arch, bool vertex_face, const NpBlock& b, unsigned char* culled) const;
};

template <class Arch>
void NpBlockKernel::operator()(Arch, bool vertex_face, const NpBlock& b,
                               unsigned char* culled) const {
  using B = xsimd::batch<double, Arch>;
  constexpr int W = static_cast<int>(B::size);
  static_assert(NpBlock::kSize % W == 0);
  struct V {
    B x, y, z;
  };
  const auto sub = [](const V& p, const V& q) { return V{p.x - q.x, p.y - q.y, p.z - q.z}; };
  const auto cross = [](const V& p, const V& q) {
    return V{p.y * q.z - p.z * q.y, p.z * q.x - p.x * q.z, p.x * q.y - p.y * q.x};
  };
  const auto dot = [](const V& p, const V& q) { return p.x * q.x + p.y * q.y + p.z * q.z; };
  const auto max_abs = [](const V& p) {
    return xsimd::max(xsimd::max(xsimd::abs(p.x), xsimd::abs(p.y)), xsimd::abs(p.z));
  };
  // Point indices of a, b, c, q (cubic_of).
  const bool vf = vertex_face;
  const int ia = vf ? 1 : 0, ib = vf ? 2 : 1, ic = vf ? 3 : 2, iq = vf ? 0 : 3;
  const B zero(0.0), one(1.0);
  const B eta_rel(256 * (DBL_EPSILON / 2)), eta_abs(1024 * __DBL_DENORM_MIN__);
  const B low(0x1p-300), high(0x1p100);
  for (int i = 0; i < b.n; i += W) {
    auto finite = (zero == zero);
    V p[8];
    for (int k = 0; k < 8; ++k) {
      p[k] = V{B::load_aligned(&b.x[k][0][i]), B::load_aligned(&b.x[k][1][i]),
               B::load_aligned(&b.x[k][2][i])};
      // x - x is 0 for finite x and NaN for infinities and NaN: allFinite.
      finite = finite & (p[k].x - p[k].x == zero) & (p[k].y - p[k].y == zero) &
               (p[k].z - p[k].z == zero);
    }
    const V* x0 = p;
    const V* x1 = p + 4;
    const V e1_0 = sub(x0[ib], x0[ia]), e2_0 = sub(x0[ic], x0[ia]);
    const V r0 = sub(x0[iq], x0[ia]);
    const V e1_1 = sub(x1[ib], x1[ia]), e2_1 = sub(x1[ic], x1[ia]);
    const V r1 = sub(x1[iq], x1[ia]);
    const V n0 = cross(e1_0, e2_0), n1 = cross(e1_1, e2_1);
    const V c01 = cross(e1_0, e2_1), c10 = cross(e1_1, e2_0);
    const V nx2{c01.x + c10.x, c01.y + c10.y, c01.z + c10.z};
    const B k0 = dot(n0, r0);
    const B k1 = (dot(nx2, r0) + dot(n0, r1)) / B(3.0);
    const B k2 = (dot(nx2, r1) + dot(n1, r0)) / B(3.0);
    const B k3 = dot(n1, r1);
    // max is exact and no difference of finite inputs is NaN, so the order of the maxima does
    // not matter.
    const B a = xsimd::max(xsimd::max(xsimd::max(max_abs(e1_0), max_abs(e2_0)),
                                      xsimd::max(max_abs(r0), max_abs(e1_1))),
                           xsimd::max(max_abs(e2_1), max_abs(r1)));
    const B e = eta_rel * (a * a * a) + eta_abs;
    const B ne = -e;
    const auto culls = ((k0 > e) & (k1 > e) & (k2 > e) & (k3 > e)) |
                       ((k0 < ne) & (k1 < ne) & (k2 < ne) & (k3 < ne));
    const auto in_range = (a >= low) & (a <= high);
    alignas(64) double out[W];
    xsimd::select(finite & in_range & culls, one, zero).store_aligned(out);
    const int lanes = b.n - i < W ? b.n - i : W;
    for (int l = 0; l < lanes; ++l)
      culled[i + l] = out[l] != 0.0 ? 1 : 0;
  }
}

}  // namespace clothcd::ccd_detail
