#include "ccd/np_batch.hpp"

#include "ccd/certify.hpp"
#include "ccd/fast_path.hpp"
#include "ccd/isa.hpp"

// Without xsimd or off x86-64 (CLOTHCD_NP_BATCH_X86 unset) the batch runs the scalar filter.

namespace clothcd::ccd_detail {

#if CLOTHCD_NP_BATCH_X86
void np_filter_batch_sse2(Kind kind, const NpBatch& b, NpVerdict* verdict);
void np_filter_batch_avx2(Kind kind, const NpBatch& b, NpVerdict* verdict);
void fast_path_misses_sse2(Kind kind, const NpBatch& b, const NpVerdict* verdict, bool* miss);
void fast_path_misses_avx2(Kind kind, const NpBatch& b, const NpVerdict* verdict, bool* miss);
void np_filter_batch_avx512(Kind kind, const NpBatch& b, NpVerdict* verdict);
void fast_path_misses_avx512(Kind kind, const NpBatch& b, const NpVerdict* verdict, bool* miss);
#endif

namespace {

void np_filter_batch_scalar(Kind kind, const NpBatch& b, NpVerdict* verdict) {
  for (int i = 0; i < b.size; ++i) {
    Eigen::Vector3d p[8];
    std::array<const Eigen::Vector3d*, 8> points;
    for (int k = 0; k < 8; ++k) {
      p[k] = {b.x[3 * k][i], b.x[3 * k + 1][i], b.x[3 * k + 2][i]};
      points[k] = &p[k];
    }
    verdict[i] = unscaled_np_filter(kind, points);
  }
}

// The kernel's own steps for one kept query (queries.cpp run, fast_path.cpp): whether every range
// of fast_path_solve's search below `b` on [lo, hi] at `level` is dropped by kMissLevel.
bool dropped(const InsideData& data, const double (&b)[4], double e, double lo, double hi,
             int level) {
  if (one_sign(b, e)) return true;
  if (level >= kFirstInsideLevel) {
    double u = 0, v = 0;
    const Inside in = inside_over(data, lo, hi, u, v);
    if (in == Inside::No) return true;
    if (level == kMissLevel || (in == Inside::Yes && sign_change(b, e))) return false;
  }
  double l[4], r[4];
  halve(b, l, r);
  const double mid = (lo + hi) * 0.5;
  return dropped(data, l, e, lo, mid, level + 1) && dropped(data, r, e, mid, hi, level + 1);
}

bool fast_path_miss_scalar(Kind kind, const std::array<const Eigen::Vector3d*, 8>& points) {
  const Motion m = make_motion(points);
  if (!(m.max_abs.maxCoeff() > 0)) return false;  // run() reports contact at t = 0
  const BernsteinCubic c = coplanarity_cubic(kind, m);
  if (np_culls(c)) return false;  // path NpCulled, not a miss
  return dropped(inside_data(kind, m), c.k, subdivision_error(c), 0.0, 1.0, 0);
}

void fast_path_misses_scalar(Kind kind, const NpBatch& b, const NpVerdict* verdict, bool* miss) {
  // Every range the search examines by kMissLevel is within its budget, none at its last level.
  static_assert(kFirstInsideLevel <= kMissLevel && kMissLevel < kFastPathMaxLevel);
  static_assert((2 << kMissLevel) - 1 <= kFastPathBudget);
  for (int i = 0; i < b.size; ++i) {
    miss[i] = false;
    if (verdict[i] != NpVerdict::Kept) continue;
    Eigen::Vector3d p[8];
    std::array<const Eigen::Vector3d*, 8> points;
    for (int k = 0; k < 8; ++k) {
      p[k] = {b.x[3 * k][i], b.x[3 * k + 1][i], b.x[3 * k + 2][i]};
      points[k] = &p[k];
    }
    miss[i] = fast_path_miss_scalar(kind, points);
  }
}

}  // namespace

void np_filter_batch(Kind kind, const NpBatch& b, NpVerdict* verdict) {
#if CLOTHCD_NP_BATCH_X86
  if (has_avx512()) {
    np_filter_batch_avx512(kind, b, verdict);
  } else if (has_avx2()) {
    np_filter_batch_avx2(kind, b, verdict);
  } else {
    np_filter_batch_sse2(kind, b, verdict);
  }
#else
  np_filter_batch_scalar(kind, b, verdict);
#endif
}

void fast_path_misses(Kind kind, const NpBatch& b, const NpVerdict* verdict, bool* miss) {
#if CLOTHCD_NP_BATCH_X86
  if (has_avx512()) {
    fast_path_misses_avx512(kind, b, verdict, miss);
  } else if (has_avx2()) {
    fast_path_misses_avx2(kind, b, verdict, miss);
  } else {
    fast_path_misses_sse2(kind, b, verdict, miss);
  }
#else
  fast_path_misses_scalar(kind, b, verdict, miss);
#endif
}

bool fast_path_misses_with(int isa, Kind kind, const NpBatch& b, const NpVerdict* verdict,
                           bool* miss) {
  switch (isa) {
    case 0:
      fast_path_misses_scalar(kind, b, verdict, miss);
      return true;
#if CLOTHCD_NP_BATCH_X86
    case 1:
      fast_path_misses_sse2(kind, b, verdict, miss);
      return true;
    case 2:
      if (!has_avx2()) return false;
      fast_path_misses_avx2(kind, b, verdict, miss);
      return true;
    case 3:
      if (!has_avx512()) return false;
      fast_path_misses_avx512(kind, b, verdict, miss);
      return true;
#endif
    default:
      return false;
  }
}

bool np_filter_batch_with(int isa, Kind kind, const NpBatch& b, NpVerdict* verdict) {
  switch (isa) {
    case 0:
      np_filter_batch_scalar(kind, b, verdict);
      return true;
#if CLOTHCD_NP_BATCH_X86
    case 1:
      np_filter_batch_sse2(kind, b, verdict);
      return true;
    case 2:
      if (!has_avx2()) return false;
      np_filter_batch_avx2(kind, b, verdict);
      return true;
    case 3:
      if (!has_avx512()) return false;
      np_filter_batch_avx512(kind, b, verdict);
      return true;
#endif
    default:
      return false;
  }
}

}  // namespace clothcd::ccd_detail
