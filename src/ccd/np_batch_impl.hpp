#pragma once
// Internal: the bodies of np_filter_batch and fast_path_settle for one xsimd architecture,
// included by one source file per instruction set (each compiled with its own target flags and
// -ffp-contract=off). Every lane repeats the scalar code (cubic_of and unscaled_np_filter in
// cubic.cpp; the kernel's fast path) operation for operation.

#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "ccd/fast_path.hpp"
#include "ccd/motion.hpp"
#include "ccd/np_batch.hpp"
#include "core/lanes.hpp"

namespace clothcd::ccd_detail {
namespace NP_BATCH_NAMESPACE {

// The 3-vector of lanes and the vector operations both routines share (lanes.hpp).
using simd::lanes::cross;
using simd::lanes::dot;
using simd::lanes::sub;
using simd::lanes::Vec3;
template <class B>
B max_abs(const Vec3<B>& p) {
  return xsimd::max(xsimd::max(xsimd::abs(p.x), xsimd::abs(p.y)), xsimd::abs(p.z));
}

// Bit l of the result: lane l of m. One movemask on SSE2 and AVX2 (xsimd has no such accessor);
// lane by lane elsewhere.
template <class Arch>
[[gnu::always_inline]] inline unsigned lane_bits(const xsimd::batch_bool<double, Arch>& m) {
#if defined(__AVX2__)
  if constexpr (std::is_same_v<Arch, xsimd::avx2>) {
    return static_cast<unsigned>(_mm256_movemask_pd(m));
  }
#endif
  if constexpr (std::is_same_v<Arch, xsimd::sse2>) {
    return static_cast<unsigned>(_mm_movemask_pd(m));
  } else {
    constexpr int W = static_cast<int>(xsimd::batch_bool<double, Arch>::size);
    bool b[W];
    m.store_unaligned(b);
    unsigned bits = 0;
    for (int l = 0; l < W; ++l)
      bits |= unsigned(b[l]) << l;
    return bits;
  }
}

// Four consecutive doubles of each lane's own record as four batches, and back: the 4 x 4
// transpose the settle's per-query rows need (W records of 32 doubles in, 32 batches of W lanes
// out). AVX2 shuffles where a batch is four doubles; element by element otherwise. Moves only.
template <class B>
[[gnu::always_inline]] inline void rows_from_records(const double* const* rec, int first, B* out) {
  constexpr int W = static_cast<int>(B::size);
#if defined(__AVX2__)
  if constexpr (W == 4 && std::is_same_v<typename B::arch_type, xsimd::avx2>) {
    const __m256d r0 = _mm256_loadu_pd(rec[0] + first), r1 = _mm256_loadu_pd(rec[1] + first);
    const __m256d r2 = _mm256_loadu_pd(rec[2] + first), r3 = _mm256_loadu_pd(rec[3] + first);
    const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
    const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    out[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
    out[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
    out[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
    out[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
    return;
  }
#endif
  alignas(64) double t[4][W];
  for (int k = 0; k < 4; ++k) {
    for (int l = 0; l < W; ++l)
      t[k][l] = rec[l][first + k];
  }
  for (int k = 0; k < 4; ++k)
    out[k] = B::load_aligned(t[k]);
}
template <class B>
[[gnu::always_inline]] inline void rows_to_records(const B* in, double* const* rec, int first) {
  constexpr int W = static_cast<int>(B::size);
#if defined(__AVX2__)
  if constexpr (W == 4 && std::is_same_v<typename B::arch_type, xsimd::avx2>) {
    const __m256d r0 = in[0], r1 = in[1], r2 = in[2], r3 = in[3];
    const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
    const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    _mm256_storeu_pd(rec[0] + first, _mm256_permute2f128_pd(t0, t2, 0x20));
    _mm256_storeu_pd(rec[1] + first, _mm256_permute2f128_pd(t1, t3, 0x20));
    _mm256_storeu_pd(rec[2] + first, _mm256_permute2f128_pd(t0, t2, 0x31));
    _mm256_storeu_pd(rec[3] + first, _mm256_permute2f128_pd(t1, t3, 0x31));
    return;
  }
#endif
  alignas(64) double t[4][W];
  for (int k = 0; k < 4; ++k)
    in[k].store_aligned(t[k]);
  for (int k = 0; k < 4; ++k) {
    for (int l = 0; l < W; ++l)
      rec[l][first + k] = t[k][l];
  }
}

// cubic.cpp cubic_of, lane by lane: the coplanarity cubic's Bernstein coefficients k and the
// largest coordinate a of the edge vectors it is built from (np_culls' error bound grows as a^3).
template <class B>
struct LaneCubic {
  B k[4];
  B a;
};
template <class B>
[[gnu::always_inline]] inline LaneCubic<B> coplanarity_cubic(Kind kind, const Vec3<B> (&x0)[4],
                                                             const Vec3<B> (&x1)[4]) {
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
    const unsigned d = lane_bits(decided), c = lane_bits(culled);
    const int n = b.size - i < W ? b.size - i : W;
    for (int l = 0; l < n; ++l) {
      verdict[i + l] = ((d >> l) & 1u) == 0   ? NpVerdict::Undecided
                       : ((c >> l) & 1u) != 0 ? NpVerdict::Culled
                                              : NpVerdict::Kept;
    }
  }
}

// The points of the n queries b.x[.][kept[l]] (n <= W; the lanes past n repeat the last), row by
// row as in NpBatch: the kept queries' gather of the settle and the distance filter.
template <int W>
void gather_kept(const NpBatch& b, const int* kept, int n, double (&col)[24][W]) {
  for (int r = 0; r < 24; ++r) {
    for (int l = 0; l < W; ++l)
      col[r][l] = b.x[r][kept[l < n ? l : n - 1]];
  }
}

// fast_path_settle's working memory, one per thread: the per-query data of a batch and the time
// ranges waiting for the inside test, a level at a time.
struct SettleScratch {
  static constexpr int kCap = NpBatch::kCapacity;
  static constexpr int kLevels = kSettleLevel + 1;
  struct Range {
    int q, j;     // kept query, range [j, j + 1] / 2^level
    double b[4];  // the cubic's Bernstein coefficients on it
  };
  // One record per query, so that a range's lanes load theirs whole (rows_from_records):
  // inside_data's five difference vectors (scaled), each at t = 0 then t = 1 (x, y, z), in rows
  // 0..29; the subdivision error e in row kE, the inside test's error in row kEin.
  static constexpr int kRow = 32, kE = 30, kEin = 31;
  alignas(64) double rec[kCap][kRow];
  bool active[kCap];  // the scaled cubic is not NP-culled
  // The ranges examined per level (bit j: range j); the earliest certified and open ranges.
  std::uint64_t examined[kCap][kLevels];
  double hit_lo[kCap], open_lo[kCap];
  int hit_level[kCap], hit_j[kCap];
  double hit_b[kCap][4];
  std::vector<Range> ranges, next;
};

// fast_path_settle (np_batch.hpp): the kernel's operations on the queries the NP filter kept, each
// lane repeating the scalar code (the sources named at each step). Scaling, the cubic and the
// first levels of halving run on W queries at a time; the inside tests, the bulk of the work, on
// W time ranges at a time, gathered from all queries of the batch (a range's lanes are rarely
// full otherwise). `target`: toi_target_level.
template <class Arch>
void fast_path_settle_impl(Kind kind, const NpBatch& b, const NpVerdict* verdict, int target,
                           FastSettled* settled, double* toi) {
  using B = xsimd::batch<double, Arch>;
  using Mask = xsimd::batch_bool<double, Arch>;
  constexpr int W = static_cast<int>(B::size);
  static_assert(NpBatch::kCapacity % W == 0);
  static_assert(kFirstInsideLevel == 2 && kSettleLevel < 64);
  using V = Vec3<B>;
  using Range = SettleScratch::Range;
  constexpr int kRow = SettleScratch::kRow;
  constexpr int kLevels = SettleScratch::kLevels;
  constexpr double kInf = std::numeric_limits<double>::infinity();
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
  thread_local SettleScratch sc;
  // The kept queries only, W at a time (a partial group repeats its last query).
  int kept[NpBatch::kCapacity];
  int nk = 0;
  for (int i = 0; i < b.size; ++i) {  // without a branch: the verdicts are unpredictable
    settled[i] = FastSettled::Run;
    toi[i] = 1.0;
    kept[nk] = i;
    nk += verdict[i] == NpVerdict::Kept ? 1 : 0;
  }
  sc.ranges.clear();
  for (int s = 0; s < nk; s += W) {
    const int n = nk - s < W ? nk - s : W;
    alignas(64) double col[24][W];
    gather_kept(b, kept + s, n, col);
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
    const Mask active = !one_sign(k, eta);
    // fast_path_solve: subdivision_error, inside_data and inside_over's bound, kept per query.
    const B kmax =
        xsimd::max(xsimd::max(xsimd::max(xsimd::abs(k[0]), xsimd::abs(k[1])), xsimd::abs(k[2])),
                   xsimd::abs(k[3]));
    const B e = eta + sub_scale * kmax;
    B row[kRow];
    B amax(0.0);
    for (int t = 0; t < 5; ++t) {
      const V d0 = sub(x0[idx[t][0]], x0[idx[t][1]]);
      const V d1 = sub(x1[idx[t][0]], x1[idx[t][1]]);
      amax = xsimd::max(amax, xsimd::max(max_abs(d0), max_abs(d1)));
      B* r = row + 6 * t;
      r[0] = d0.x, r[1] = d0.y, r[2] = d0.z, r[3] = d1.x, r[4] = d1.y, r[5] = d1.z;
    }
    const B mm = amax * widen;
    row[SettleScratch::kE] = e;
    row[SettleScratch::kEin] = in_scale * (mm * mm) * (mm * mm) + in_floor;
    {
      // Lanes past n write the records of queries past nk, which nothing reads.
      double* dst[W];
      for (int l = 0; l < W; ++l)
        dst[l] = sc.rec[s + l];
      for (int k = 0; k < kRow; k += 4)
        rows_to_records(row + k, dst, k);
    }
    // The search's first levels (no inside test before kFirstInsideLevel): the whole step, its
    // halves, its quarters, each examined where the cubic is not of one sign on it and its
    // parent was.
    B half_b[2][4], quarter_b[4][4];
    const Mask open0 = active && !one_sign(k, e);
    halve(k, half_b[0], half_b[1]);
    Mask open1[2], open2[4];
    for (int h = 0; h < 2; ++h) {
      open1[h] = open0 && !one_sign(half_b[h], e);
      halve(half_b[h], quarter_b[2 * h], quarter_b[2 * h + 1]);
      open2[2 * h] = open1[h] && !one_sign(quarter_b[2 * h], e);
      open2[2 * h + 1] = open1[h] && !one_sign(quarter_b[2 * h + 1], e);
    }
    const unsigned act = lane_bits(active), o0 = lane_bits(open0);
    const unsigned o1[2] = {lane_bits(open1[0]), lane_bits(open1[1])};
    unsigned o2[4];
    alignas(64) double qb[4][4][W];
    for (int j = 0; j < 4; ++j) {
      o2[j] = lane_bits(open2[j]);
      for (int c = 0; c < 4; ++c)
        quarter_b[j][c].store_aligned(qb[j][c]);
    }
    for (int l = 0; l < n; ++l) {
      const int q = s + l;
      sc.active[q] = ((act >> l) & 1u) != 0;
      sc.hit_lo[q] = sc.open_lo[q] = kInf;
      std::uint64_t* ex = sc.examined[q];
      for (int v = 0; v < kLevels; ++v)
        ex[v] = 0;
      ex[0] = (o0 >> l) & 1u;
      ex[1] = ((o1[0] >> l) & 1u) | ((o1[1] >> l) & 1u) << 1;
      for (int j = 0; j < 4; ++j) {
        if (((o2[j] >> l) & 1u) != 0)
          sc.ranges.push_back(Range{q, j, {qb[j][0][l], qb[j][1][l], qb[j][2][l], qb[j][3][l]}});
      }
    }
  }
  // fast_path_solve's search, level by level from kFirstInsideLevel: it drops a range where the
  // inside answer is No, certifies a hit where it is Yes and the cubic changes sign, and splits
  // it otherwise into the halves on which the cubic is not of one sign (below kSettleLevel;
  // deeper ranges are left to the kernel: "open"). Its depth-first order reaches a range after
  // every earlier one and the ranges containing it. So a query is a miss when nothing is
  // certified or open and it examined at most kFastPathBudget ranges, and a hit in its earliest
  // certified range H when no open range starts before H and at most kFastPathBudget examined
  // ranges start at or before H (the earlier ranges, the ranges containing H, and H). Ranges
  // starting at or after a query's earliest certified or open range cannot change its answer
  // and are not followed.
  struct Verdict {
    Mask no, yes;
  };
  for (int level = kFirstInsideLevel; level <= kSettleLevel && !sc.ranges.empty(); ++level) {
    const double width = 1.0 / (1 << level);
    sc.next.clear();
    const std::size_t count = sc.ranges.size();
    std::size_t r = 0;
    while (r < count) {
      // The next W ranges still worth examining (a partial group repeats its last range).
      const Range* g[W];
      int m = 0;
      for (; r < count && m < W; ++r) {
        const Range& rg = sc.ranges[r];
        if (width * rg.j < std::min(sc.hit_lo[rg.q], sc.open_lo[rg.q])) g[m++] = &rg;
      }
      if (m == 0) break;
      for (int l = m; l < W; ++l)
        g[l] = g[m - 1];
      // The lanes' query records and Bernstein coefficients, transposed into rows.
      B row[kRow], cb[4];
      {
        const double* src[W];
        for (int l = 0; l < W; ++l)
          src[l] = sc.rec[g[l]->q];
        for (int k = 0; k < kRow; k += 4)
          rows_from_records(src, k, row + k);
        for (int l = 0; l < W; ++l)
          src[l] = g[l]->b;
        rows_from_records(src, 0, cb);
      }
      V d0[5], d1[5];
      for (int t = 0; t < 5; ++t) {
        const B* r = row + 6 * t;
        d0[t] = V{r[0], r[1], r[2]};
        d1[t] = V{r[3], r[4], r[5]};
      }
      const B e = row[SettleScratch::kE], ein = row[SettleScratch::kEin];
      // The range [j, j + 1] 2^-level as width * j and width * (j + 1): j and j + 1 are exact.
      alignas(64) double lane_j[W], lane_lo[W];
      for (int l = 0; l < W; ++l)
        lane_j[l] = g[l]->j;
      const B jb = B::load_aligned(lane_j);
      const B lo = B(width) * jb, hi = B(width) * (jb + B(1.0));
      lo.store_aligned(lane_lo);
      // inside_over over [lo, hi]: No (a function below -ein), Yes (all above ein). As soon as
      // every lane is No the other functions cannot change that, and Yes matters only where the
      // answer is not No: stop there.
      const auto below = [&](const I& f) { return f.m + f.r < -ein; };
      const auto above = [&](const I& f) { return f.m - f.r > ein; };
      const auto at = [&](int t) {
        const auto one = [&](const B& p0, const B& p1) {
          const B dx = p1 - p0;
          const B p = p0 + lo * dx, q = p0 + hi * dx;
          return I{(p + q) * half, xsimd::abs(q - p) * half};
        };
        return IV{one(d0[t].x, d1[t].x), one(d0[t].y, d1[t].y), one(d0[t].z, d1[t].z)};
      };
      const Verdict in = [&] {
        Verdict v{Mask(false), Mask(true)};
        const auto add = [&](const I& f) {
          v.no = v.no || below(f);
          v.yes = v.yes && above(f);
          return xsimd::all(v.no);
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
      }();
      const Mask left = !in.no;
      const Mask change = ((cb[0] > e) && (cb[3] < -e)) || ((cb[0] < -e) && (cb[3] > e));
      const Mask hit = left && in.yes && change;
      const Mask split = left && !hit;
      const unsigned lf = lane_bits(left), ht = lane_bits(hit);
      unsigned sl = 0, sr = 0;
      alignas(64) double kb[2][4][W];
      if (level < kSettleLevel && xsimd::any(split)) {
        B lb[4], rb[4];
        halve(cb, lb, rb);
        sl = lane_bits(split && !one_sign(lb, e));
        sr = lane_bits(split && !one_sign(rb, e));
        for (int c = 0; c < 4; ++c) {
          lb[c].store_aligned(kb[0][c]);
          rb[c].store_aligned(kb[1][c]);
        }
      }
      for (int l = 0; l < m; ++l) {
        const Range& rg = *g[l];
        const int q = rg.q;
        sc.examined[q][level] |= std::uint64_t(1) << rg.j;
        if (((lf >> l) & 1u) == 0) continue;
        const double lo_t = lane_lo[l];
        if (((ht >> l) & 1u) != 0) {
          if (lo_t < sc.hit_lo[q]) {
            sc.hit_lo[q] = lo_t;
            sc.hit_level[q] = level;
            sc.hit_j[q] = rg.j;
            for (int c = 0; c < 4; ++c)
              sc.hit_b[q][c] = rg.b[c];
          }
          continue;
        }
        if (level == kSettleLevel) {
          sc.open_lo[q] = std::min(sc.open_lo[q], lo_t);
          continue;
        }
        if (((sl >> l) & 1u) != 0) {
          sc.next.push_back(
              Range{q, 2 * rg.j, {kb[0][0][l], kb[0][1][l], kb[0][2][l], kb[0][3][l]}});
        }
        if (((sr >> l) & 1u) != 0) {
          sc.next.push_back(
              Range{q, 2 * rg.j + 1, {kb[1][0][l], kb[1][1][l], kb[1][2][l], kb[1][3][l]}});
        }
      }
    }
    std::swap(sc.ranges, sc.next);
  }
  for (int q = 0; q < nk; ++q) {
    if (!sc.active[q]) continue;
    const std::uint64_t* ex = sc.examined[q];
    if (sc.hit_lo[q] == kInf) {
      // Nothing was left unfollowed (no certified or open range): every range is counted.
      if (sc.open_lo[q] != kInf) continue;
      int total = 0;
      for (int v = 0; v < kLevels; ++v)
        total += std::popcount(ex[v]);
      if (total <= kFastPathBudget) settled[kept[q]] = FastSettled::Miss;
      continue;
    }
    if (!(sc.hit_lo[q] < sc.open_lo[q])) continue;
    // The examined ranges that start at or before H = (hit_level, hit_j): at level v, indices up
    // to hit_j scaled to that level.
    const int hv = sc.hit_level[q], hj = sc.hit_j[q];
    int before = 0;
    for (int v = 0; v < kLevels; ++v) {
      const std::uint64_t last =
          v <= hv ? std::uint64_t(hj) >> (hv - v) : std::uint64_t(hj) << (v - hv);
      const std::uint64_t upto = last >= 63 ? ~std::uint64_t(0) : (std::uint64_t(2) << last) - 1;
      before += std::popcount(ex[v] & upto);
    }
    if (before > kFastPathBudget) continue;
    const double width = 1.0 / (1 << hv);
    toi[kept[q]] = first_root_bound(sc.hit_b[q], width * hj, width * (hj + 1), hv,
                                    sc.rec[q][SettleScratch::kE], hv > target ? hv : target);
    settled[kept[q]] = FastSettled::Hit;
  }
}

}  // namespace NP_BATCH_NAMESPACE
}  // namespace clothcd::ccd_detail
