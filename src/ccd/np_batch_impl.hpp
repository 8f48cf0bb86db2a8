#pragma once
// Internal: the bodies of np_filter_batch and fast_path_settle for one xsimd architecture,
// included by one source file per instruction set (each compiled with its own target flags and
// -ffp-contract=off). Every lane repeats the scalar code (cubic_of and unscaled_np_filter in
// cubic.cpp; the kernel's fast path) operation for operation.

#include <xsimd/xsimd.hpp>

#include <bit>
#include <cfloat>
#include <cstdint>
#include <limits>

#include "ccd/fast_path.hpp"
#include "ccd/lanes.hpp"
#include "ccd/motion.hpp"
#include "ccd/np_batch.hpp"

namespace clothcd::ccd_detail {
namespace NP_BATCH_NAMESPACE {

// The 3-vector of lanes and the vector operations both routines share (lanes.hpp).
using lanes::cross;
using lanes::dot;
using lanes::sub;
using lanes::Vec3;
template <class B>
B max_abs(const Vec3<B>& p) {
  return xsimd::max(xsimd::max(xsimd::abs(p.x), xsimd::abs(p.y)), xsimd::abs(p.z));
}

// cubic.cpp cubic_of, lane by lane: the coplanarity cubic's Bernstein coefficients k and the
// largest coordinate a of the edge vectors it is built from (np_culls' error bound grows as a^3).
template <class B>
struct LaneCubic {
  B k[4];
  B a;
};
template <class B>
LaneCubic<B> coplanarity_cubic(Kind kind, const Vec3<B> (&x0)[4], const Vec3<B> (&x1)[4]) {
  // Point indices of a, b, c, q (as in cubic_of).
  const int ia = kind == Kind::VertexFace ? 1 : 0;
  const int ib = kind == Kind::VertexFace ? 2 : 1;
  const int ic = kind == Kind::VertexFace ? 3 : 2;
  const int iq = kind == Kind::VertexFace ? 0 : 3;
  const B third(3.0);
  const Vec3<B> e1_0 = sub(x0[ib], x0[ia]), e2_0 = sub(x0[ic], x0[ia]);
  const Vec3<B> r0 = sub(x0[iq], x0[ia]);
  const Vec3<B> e1_1 = sub(x1[ib], x1[ia]), e2_1 = sub(x1[ic], x1[ia]);
  const Vec3<B> r1 = sub(x1[iq], x1[ia]);
  const Vec3<B> n0 = cross(e1_0, e2_0), n1 = cross(e1_1, e2_1);
  const Vec3<B> c01 = cross(e1_0, e2_1), c10 = cross(e1_1, e2_0);
  const Vec3<B> nx2 = {c01.x + c10.x, c01.y + c10.y, c01.z + c10.z};
  // The maximum is exact whatever the order (finite lanes; the others are undecided).
  return {{dot(n0, r0), (dot(nx2, r0) + dot(n0, r1)) / third, (dot(nx2, r1) + dot(n1, r0)) / third,
           dot(n1, r1)},
          xsimd::max(xsimd::max(xsimd::max(max_abs(e1_0), max_abs(e2_0)),
                                xsimd::max(max_abs(r0), max_abs(e1_1))),
                     xsimd::max(max_abs(e2_1), max_abs(r1)))};
}

template <class Arch>
void np_filter_batch_impl(Kind kind, const NpBatch& b, NpVerdict* verdict) {
  using B = xsimd::batch<double, Arch>;
  using Mask = xsimd::batch_bool<double, Arch>;
  constexpr int W = static_cast<int>(B::size);
  static_assert(NpBatch::kCapacity % W == 0);
  const B big(DBL_MAX);
  const B eta_scale(256 * (DBL_EPSILON / 2));
  const B eta_floor(1024 * std::numeric_limits<double>::denorm_min());
  const B low(0x1p-300), high(0x1p100);
  for (int i = 0; i < b.size; i += W) {
    using V = Vec3<B>;
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
    const LaneCubic<B> cubic = coplanarity_cubic(kind, x0, x1);
    const B a = cubic.a;
    const B e = eta_scale * (a * a * a) + eta_floor;
    const Mask decided = finite && (a >= low) && (a <= high);
    const Mask culled = one_sign(cubic.k, e);
    bool d[W], c[W];
    decided.store_unaligned(d);
    culled.store_unaligned(c);
    const int n = b.size - i < W ? b.size - i : W;
    for (int l = 0; l < n; ++l) {
      verdict[i + l] = !d[l] ? NpVerdict::Undecided : (c[l] ? NpVerdict::Culled : NpVerdict::Kept);
    }
  }
}

// fast_path_settle (np_batch.hpp): lane by lane, the kernel's operations on a query the NP filter
// kept, from make_motion's scaling to the inside tests of the search down to kSettleLevel, each
// as the scalar code performs it (the sources named at each step). `target`: toi_target_level.
template <class Arch>
void fast_path_settle_impl(Kind kind, const NpBatch& b, const NpVerdict* verdict, int target,
                           FastSettled* settled, double* toi) {
  using B = xsimd::batch<double, Arch>;
  using Mask = xsimd::batch_bool<double, Arch>;
  constexpr int W = static_cast<int>(B::size);
  static_assert(NpBatch::kCapacity % W == 0);
  using V = Vec3<B>;
  struct I {  // certify.cpp's midpoint-radius interval
    B m, r;
  };
  struct IV {
    I x, y, z;
  };
  // inside_data's difference vectors (point index pairs).
  static constexpr int kVf[5][2] = {{2, 1}, {3, 1}, {0, 1}, {3, 2}, {0, 2}};
  static constexpr int kEe[5][2] = {{1, 0}, {3, 2}, {2, 0}, {1, 2}, {0, 3}};
  const auto& idx = kind == Kind::VertexFace ? kVf : kEe;
  constexpr double u = DBL_EPSILON / 2;
  const B half(0.5);
  const B eta_scale(256 * u), eta_floor(1024 * std::numeric_limits<double>::denorm_min());
  const B sub_scale(128 * u);
  const B in_scale(2048 * u), in_floor(16384 * std::numeric_limits<double>::denorm_min());
  const B widen(1 + 1e-12);
  const auto imul = [](const I& p, const I& q) {
    return I{p.m * q.m, xsimd::abs(p.m) * q.r + xsimd::abs(q.m) * p.r + p.r * q.r};
  };
  const auto isub = [](const I& p, const I& q) { return I{p.m - q.m, p.r + q.r}; };
  const auto iadd = [](const I& p, const I& q) { return I{p.m + q.m, p.r + q.r}; };
  const auto icross = [&](const IV& p, const IV& q) {
    return IV{isub(imul(p.y, q.z), imul(p.z, q.y)), isub(imul(p.z, q.x), imul(p.x, q.z)),
              isub(imul(p.x, q.y), imul(p.y, q.x))};
  };
  const auto idot = [&](const IV& p, const IV& q) {
    return iadd(iadd(imul(p.x, q.x), imul(p.y, q.y)), imul(p.z, q.z));
  };
  // The kept queries only, W at a time (a partial group repeats its last query).
  int kept[NpBatch::kCapacity];
  int nk = 0;
  for (int i = 0; i < b.size; ++i) {  // without a branch: the verdicts are unpredictable
    settled[i] = FastSettled::Run;
    toi[i] = 1.0;
    kept[nk] = i;
    nk += verdict[i] == NpVerdict::Kept ? 1 : 0;
  }
  for (int s = 0; s < nk; s += W) {
    const int n = nk - s < W ? nk - s : W;
    alignas(64) double col[24][W];
    for (int r = 0; r < 24; ++r) {
      for (int l = 0; l < W; ++l)
        col[r][l] = b.x[r][kept[s + (l < n ? l : n - 1)]];
    }
    // make_motion: the largest |coordinate| and its power-of-two scale (inverse_binade, per lane).
    // Kept queries are finite with coordinate differences of at least 2^-300, so the largest
    // |coordinate| is positive and run() goes on to the cubic.
    B top(0.0);
    for (int r = 0; r < 24; ++r)
      top = xsimd::max(top, xsimd::abs(B::load_aligned(col[r])));
    alignas(64) double lane_top[W], lane_scale[W];
    top.store_aligned(lane_top);
    for (int l = 0; l < W; ++l)
      lane_scale[l] = inverse_binade(lane_top[l]);
    const B scale = B::load_aligned(lane_scale);
    V x0[4], x1[4];
    for (int p = 0; p < 4; ++p) {
      x0[p] = V{B::load_aligned(col[3 * p]) * scale, B::load_aligned(col[3 * p + 1]) * scale,
                B::load_aligned(col[3 * p + 2]) * scale};
      x1[p] = V{B::load_aligned(col[3 * p + 12]) * scale, B::load_aligned(col[3 * p + 13]) * scale,
                B::load_aligned(col[3 * p + 14]) * scale};
    }
    // coplanarity_cubic (cubic.cpp cubic_of) and np_culls.
    const LaneCubic<B> cubic = coplanarity_cubic(kind, x0, x1);
    const B(&k)[4] = cubic.k;
    const B a = cubic.a;
    const B eta = eta_scale * (a * a * a) + eta_floor;
    const Mask np_culled = one_sign(k, eta);
    // fast_path_solve: subdivision_error, then the ranges down to the quarters of the step
    // (kFirstInsideLevel), each dropped where the cubic keeps one sign on it or on its parent.
    const B kmax =
        xsimd::max(xsimd::max(xsimd::max(xsimd::abs(k[0]), xsimd::abs(k[1])), xsimd::abs(k[2])),
                   xsimd::abs(k[3]));
    const B e = eta + sub_scale * kmax;
    // inside_data and inside_over's bound.
    V d0[5], d1[5];
    B amax(0.0);
    for (int j = 0; j < 5; ++j) {
      d0[j] = sub(x0[idx[j][0]], x0[idx[j][1]]);
      d1[j] = sub(x1[idx[j][0]], x1[idx[j][1]]);
      amax = xsimd::max(amax, xsimd::max(max_abs(d0[j]), max_abs(d1[j])));
    }
    const B mm = amax * widen;
    const B ein = in_scale * (mm * mm) * (mm * mm) + in_floor;
    const auto below = [&](const I& g) { return g.m + g.r < -ein; };
    const auto above = [&](const I& g) { return g.m - g.r > ein; };
    struct Verdict {
      Mask no, yes;
    };
    // inside_over over [lo, hi] in the lanes `need`: No (a function below -ein), Yes (all above
    // ein). As soon as every such lane is No the other functions cannot change that, and Yes
    // matters only where the answer is not No: stop there.
    const auto inside = [&](double lo_t, double hi_t, const Mask& need) {
      const B lo(lo_t), hi(hi_t);
      const auto at = [&](int t) {
        const auto one = [&](const B& p0, const B& p1) {
          const B dx = p1 - p0;
          const B p = p0 + lo * dx, r = p0 + hi * dx;
          return I{(p + r) * half, xsimd::abs(r - p) * half};
        };
        return IV{one(d0[t].x, d1[t].x), one(d0[t].y, d1[t].y), one(d0[t].z, d1[t].z)};
      };
      Verdict v{Mask(false), Mask(true)};
      const auto add = [&](const I& g) {
        v.no = v.no || below(g);
        v.yes = v.yes && above(g);
        return xsimd::none(need && !v.no);
      };
      const IV x0 = at(0), x1 = at(1), x2 = at(2);
      const IV nn = icross(x0, x1);
      if (kind == Kind::VertexFace) {
        if (add(idot(nn, icross(x0, x2)))) return v;
        const IV x3 = at(3), x4 = at(4);
        if (add(idot(nn, icross(x3, x4)))) return v;
        add(idot(nn, icross(x2, x1)));
        return v;
      }
      if (add(idot(nn, icross(x2, x1)))) return v;
      const IV x3 = at(3);
      if (add(idot(nn, icross(x3, x1)))) return v;
      if (add(idot(nn, icross(x2, x0)))) return v;
      add(idot(nn, icross(at(4), x0)));
      return v;
    };
    // fast_path_solve's search, level by level: range j of a level spans [j, j + 1] / 2^level.
    // The kernel examines every range whose parent it splits unless the cubic keeps one sign on
    // it; from kFirstInsideLevel on it drops the range where the inside answer is No, certifies
    // a hit where it is Yes and the cubic changes sign, and splits it otherwise (below
    // kSettleLevel; deeper ranges are left to it: "open"). Its depth-first order reaches a range
    // after every earlier one and the ranges containing it. So a lane is a miss when nothing is
    // certified or open and it examined at most kFastPathBudget ranges, and a hit in its
    // earliest certified range H when no open range starts before H and at most
    // kFastPathBudget examined ranges start at or before H (the earlier ranges, the ranges
    // containing H, and H). Ranges starting at or after a lane's earliest certified or open
    // range cannot change its answer and are not followed.
    constexpr int kSlots = 1 << kSettleLevel;
    static_assert(kSlots <= 64);
    constexpr int kLevels = kSettleLevel + 1;
    B coef[2][kSlots][4];  // this level's ranges and the next one's, alternately
    Mask open[2][kSlots];  // valid where the level's `slots` bit is set
    int now = 0;
    const Mask active = !np_culled;
    const B inf(std::numeric_limits<double>::infinity());
    B hit_lo = inf, open_lo = inf;  // start of the earliest certified, open range
    // The ranges examined: how many per lane, in which lanes (seen, valid where the level's
    // seen_slots bit is set); and per lane the earliest certified range's level, index and
    // coefficients.
    const B one(1.0), zero(0.0);
    B examined(0.0);
    Mask seen[kLevels][kSlots];
    std::uint64_t seen_slots[kLevels] = {};
    int hit_level[W] = {}, hit_j[W] = {};
    double hit_b[W][4] = {};
    for (int c = 0; c < 4; ++c)
      coef[0][0][c] = k[c];
    open[0][0] = active && !one_sign(k, e);
    // The ranges open in some lane, one bit each: only those are visited.
    std::uint64_t slots = xsimd::any(open[0][0]) ? 1u : 0u;
    for (int level = 0; level <= kSettleLevel && slots != 0; ++level) {
      const int count = 1 << level;
      const double width = 1.0 / count;
      B(&cur)[kSlots][4] = coef[now];
      B(&nxt)[kSlots][4] = coef[1 - now];
      const Mask* cur_open = open[now];
      Mask* nxt_open = open[1 - now];
      std::uint64_t next_slots = 0;
      for (std::uint64_t bits = slots; bits != 0; bits &= bits - 1) {
        const int j = std::countr_zero(bits);
        const double lo_t = width * j;
        const Mask need = cur_open[j] && (B(lo_t) < xsimd::min(hit_lo, open_lo));
        if (xsimd::none(need)) continue;
        examined = examined + xsimd::select(need, one, zero);
        seen[level][j] = need;
        seen_slots[level] |= std::uint64_t(1) << j;
        Mask split = need;
        if (level >= kFirstInsideLevel) {
          const Verdict in = inside(lo_t, width * (j + 1), need);
          const Mask left = need && !in.no;
          const Mask change =
              ((cur[j][0] > e) && (cur[j][3] < -e)) || ((cur[j][0] < -e) && (cur[j][3] > e));
          const Mask hit = left && in.yes && change;
          if (xsimd::any(hit)) {
            // The earliest so far in these lanes: ranges are visited in time order per level,
            // and need keeps only ranges before the lane's earliest certified one.
            hit_lo = xsimd::select(hit, B(lo_t), hit_lo);
            bool hb[W];
            hit.store_unaligned(hb);
            alignas(64) double cb[4][W];
            for (int c = 0; c < 4; ++c)
              cur[j][c].store_aligned(cb[c]);
            for (int l = 0; l < W; ++l) {
              if (!hb[l]) continue;
              hit_level[l] = level;
              hit_j[l] = j;
              for (int c = 0; c < 4; ++c)
                hit_b[l][c] = cb[c][l];
            }
          }
          split = left && !hit;
          if (level == kSettleLevel) {
            open_lo = xsimd::select(split, xsimd::min(open_lo, B(lo_t)), open_lo);
            continue;
          }
          if (xsimd::none(split)) continue;
        }
        halve(cur[j], nxt[2 * j], nxt[2 * j + 1]);
        nxt_open[2 * j] = split && !one_sign(nxt[2 * j], e);
        nxt_open[2 * j + 1] = split && !one_sign(nxt[2 * j + 1], e);
        next_slots |= std::uint64_t(xsimd::any(nxt_open[2 * j])) << (2 * j);
        next_slots |= std::uint64_t(xsimd::any(nxt_open[2 * j + 1])) << (2 * j + 1);
      }
      slots = next_slots;
      now = 1 - now;
    }
    bool act[W];
    active.store_unaligned(act);
    alignas(64) double hl[W], ol[W], el[W], count[W];
    hit_lo.store_aligned(hl);
    open_lo.store_aligned(ol);
    e.store_aligned(el);
    examined.store_aligned(count);
    for (int l = 0; l < n; ++l) {
      if (!act[l]) continue;
      const int q = kept[s + l];
      if (hl[l] == std::numeric_limits<double>::infinity()) {
        // Nothing was left unvisited (no certified or open range): count is every range.
        const bool dropped = ol[l] == std::numeric_limits<double>::infinity();
        if (dropped && count[l] <= kFastPathBudget) settled[q] = FastSettled::Miss;
        continue;
      }
      if (!(hl[l] < ol[l])) continue;
      // The ranges examined in this lane that start at or before H = (hit_level, hit_j): at
      // level v, indices up to hit_j scaled to that level.
      const int hv = hit_level[l], hj = hit_j[l];
      int before = 0;
      for (int v = 0; v < kLevels; ++v) {
        const std::uint64_t last =
            v <= hv ? std::uint64_t(hj) >> (hv - v) : std::uint64_t(hj) << (v - hv);
        const std::uint64_t upto = last >= 63 ? ~std::uint64_t(0) : (std::uint64_t(2) << last) - 1;
        for (std::uint64_t bits = seen_slots[v] & upto; bits != 0; bits &= bits - 1) {
          bool lanes[W];
          seen[v][std::countr_zero(bits)].store_unaligned(lanes);
          before += lanes[l] ? 1 : 0;
        }
      }
      if (before > kFastPathBudget) continue;
      const double width = 1.0 / (1 << hv);
      toi[q] = first_root_bound(hit_b[l], width * hj, width * (hj + 1), hv, el[l],
                                hv > target ? hv : target);
      settled[q] = FastSettled::Hit;
    }
  }
}

}  // namespace NP_BATCH_NAMESPACE
}  // namespace clothcd::ccd_detail
