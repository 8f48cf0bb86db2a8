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
// of fast_path_solve's search below `b` on [lo, hi] at `level` is dropped by kMissLevel, counting
// in `examined` the ranges the search examines (those not of one sign).
bool dropped(const InsideData& data, const double (&b)[4], double e, double lo, double hi,
             int level, int& examined) {
  if (one_sign(b, e)) return true;
  ++examined;
  if (level >= kFirstInsideLevel) {
    double u = 0, v = 0;
    const Inside in = inside_over(data, lo, hi, u, v);
    if (in == Inside::No) return true;
    if (level == kMissLevel || (in == Inside::Yes && sign_change(b, e))) return false;
  }
  double l[4], r[4];
  halve(b, l, r);
  const double mid = (lo + hi) * 0.5;
  return dropped(data, l, e, lo, mid, level + 1, examined) &&
         dropped(data, r, e, mid, hi, level + 1, examined);
}

bool fast_path_miss_scalar(Kind kind, const std::array<const Eigen::Vector3d*, 8>& points) {
  const Motion m = make_motion(points);
  if (!(m.max_abs.maxCoeff() > 0)) return false;  // run() reports contact at t = 0
  const BernsteinCubic c = coplanarity_cubic(kind, m);
  if (np_culls(c)) return false;  // path NpCulled, not a miss
  // Past its budget the kernel hands the rest of the step to the inclusion solver: not a miss.
  int examined = 0;
  return dropped(inside_data(kind, m), c.k, subdivision_error(c), 0.0, 1.0, 0, examined) &&
         examined <= kFastPathBudget;
}

void fast_path_misses_scalar(Kind kind, const NpBatch& b, const NpVerdict* verdict, bool* miss) {
  // No range the search examines by kMissLevel is at its last level (the inclusion solver's).
  static_assert(kFirstInsideLevel <= kMissLevel && kMissLevel < kFastPathMaxLevel);
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

#if CLOTHCD_NP_BATCH_X86
constexpr void (*const kNp[4])(Kind, const NpBatch&, NpVerdict*) = {
    np_filter_batch_scalar, np_filter_batch_sse2, np_filter_batch_avx2, np_filter_batch_avx512};
constexpr void (*const kMiss[4])(Kind, const NpBatch&, const NpVerdict*, bool*) = {
    fast_path_misses_scalar, fast_path_misses_sse2, fast_path_misses_avx2, fast_path_misses_avx512};
#else
constexpr void (*const kNp[4])(Kind, const NpBatch&, NpVerdict*) = {np_filter_batch_scalar, nullptr,
                                                                    nullptr, nullptr};
constexpr void (*const kMiss[4])(Kind, const NpBatch&, const NpVerdict*, bool*) = {
    fast_path_misses_scalar, nullptr, nullptr, nullptr};
#endif

}  // namespace

void np_filter_batch(Kind kind, const NpBatch& b, NpVerdict* verdict) {
  run_on(-1, kNp, kind, b, verdict);
}

void fast_path_misses(Kind kind, const NpBatch& b, const NpVerdict* verdict, bool* miss) {
  run_on(-1, kMiss, kind, b, verdict, miss);
}

bool fast_path_misses_with(int isa, Kind kind, const NpBatch& b, const NpVerdict* verdict,
                           bool* miss) {
  return isa >= 0 && run_on(isa, kMiss, kind, b, verdict, miss);
}

bool np_filter_batch_with(int isa, Kind kind, const NpBatch& b, NpVerdict* verdict) {
  return isa >= 0 && run_on(isa, kNp, kind, b, verdict);
}

}  // namespace clothcd::ccd_detail
