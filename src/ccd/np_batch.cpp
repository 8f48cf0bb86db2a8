#include "ccd/np_batch.hpp"

#include "ccd/certify.hpp"
#include "ccd/fast_path.hpp"
#include "clothcd/ccd/queries.hpp"
#include "core/isa.hpp"

// Without xsimd or off x86-64 (CLOTHCD_SIMD_X86 unset) the batch runs the scalar filter.

namespace clothcd::ccd_detail {

#if CLOTHCD_SIMD_X86
void np_filter_batch_sse2(Kind kind, const NpBatch& b, NpVerdict* verdict);
void np_filter_batch_avx2(Kind kind, const NpBatch& b, NpVerdict* verdict);
void fast_path_settle_sse2(Kind kind, const NpBatch& b, const NpVerdict* verdict, int target,
                           FastSettled* settled, double* toi);
void fast_path_settle_avx2(Kind kind, const NpBatch& b, const NpVerdict* verdict, int target,
                           FastSettled* settled, double* toi);
void np_filter_batch_avx512(Kind kind, const NpBatch& b, NpVerdict* verdict);
void distance_filter_batch_sse2(Kind kind, const NpBatch& b, double thickness, int depth,
                                NpVerdict* verdict);
void distance_filter_batch_avx2(Kind kind, const NpBatch& b, double thickness, int depth,
                                NpVerdict* verdict);
void distance_filter_batch_avx512(Kind kind, const NpBatch& b, double thickness, int depth,
                                  NpVerdict* verdict);
void fast_path_settle_avx512(Kind kind, const NpBatch& b, const NpVerdict* verdict, int target,
                             FastSettled* settled, double* toi);
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

void distance_filter_batch_scalar(Kind kind, const NpBatch& b, double thickness, int depth,
                                  NpVerdict* verdict) {
  for (int i = 0; i < b.size; ++i) {
    if (verdict[i] != NpVerdict::Kept) continue;
    Eigen::Vector3d p[8];
    for (int k = 0; k < 8; ++k)
      p[k] = {b.x[3 * k][i], b.x[3 * k + 1][i], b.x[3 * k + 2][i]};
    const bool culled =
        kind == Kind::VertexFace
            ? distance_filter_culls(VertexFaceQuery{p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]},
                                    thickness, depth)
            : distance_filter_culls(EdgeEdgeQuery{p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]},
                                    thickness, depth);
    if (culled) verdict[i] = NpVerdict::Culled;
  }
}

// The kernel's own steps for one kept query (queries.cpp run, then fast_path_solve's search),
// stopping where the search would call the inclusion solver or go below kSettleLevel (Run).
FastSettled settle_scalar(Kind kind, const std::array<const Eigen::Vector3d*, 8>& points,
                          int target, double& toi) {
  const Motion m = make_motion(points);
  if (!(m.max_abs.maxCoeff() > 0)) return FastSettled::Run;  // run() reports contact at t = 0
  const BernsteinCubic c = coplanarity_cubic(kind, m);
  if (np_culls(c)) return FastSettled::Run;  // path NpCulled
  FastOutcome out;
  if (!fast_path_search(kind, m, c, target, kSettleLevel, out)) return FastSettled::Run;
  if (!out.hit) return FastSettled::Miss;
  toi = out.toi;
  return FastSettled::Hit;
}

void settle_batch_scalar(Kind kind, const NpBatch& b, const NpVerdict* verdict, int target,
                         FastSettled* settled, double* toi) {
  // No range the search examines by kSettleLevel is at its last level (the inclusion solver's).
  static_assert(kFirstInsideLevel <= kSettleLevel && kSettleLevel < kFastPathMaxLevel);
  for (int i = 0; i < b.size; ++i) {
    settled[i] = FastSettled::Run;
    toi[i] = 1.0;
    if (verdict[i] != NpVerdict::Kept) continue;
    Eigen::Vector3d p[8];
    std::array<const Eigen::Vector3d*, 8> points;
    for (int k = 0; k < 8; ++k) {
      p[k] = {b.x[3 * k][i], b.x[3 * k + 1][i], b.x[3 * k + 2][i]};
      points[k] = &p[k];
    }
    settled[i] = settle_scalar(kind, points, target, toi[i]);
  }
}

#if CLOTHCD_SIMD_X86
constexpr void (*const kNp[4])(Kind, const NpBatch&, NpVerdict*) = {
    np_filter_batch_scalar, np_filter_batch_sse2, np_filter_batch_avx2, np_filter_batch_avx512};
constexpr void (*const kSettle[4])(Kind, const NpBatch&, const NpVerdict*, int, FastSettled*,
                                   double*) = {settle_batch_scalar, fast_path_settle_sse2,
                                               fast_path_settle_avx2, fast_path_settle_avx512};
constexpr void (*const kDistance[4])(Kind, const NpBatch&, double, int, NpVerdict*) = {
    distance_filter_batch_scalar, distance_filter_batch_sse2, distance_filter_batch_avx2,
    distance_filter_batch_avx512};
#else
constexpr void (*const kNp[4])(Kind, const NpBatch&, NpVerdict*) = {np_filter_batch_scalar, nullptr,
                                                                    nullptr, nullptr};
constexpr void (*const kSettle[4])(Kind, const NpBatch&, const NpVerdict*, int, FastSettled*,
                                   double*) = {settle_batch_scalar, nullptr, nullptr, nullptr};
constexpr void (*const kDistance[4])(Kind, const NpBatch&, double, int, NpVerdict*) = {
    distance_filter_batch_scalar, nullptr, nullptr, nullptr};
#endif

}  // namespace

void np_filter_batch(Kind kind, const NpBatch& b, NpVerdict* verdict) {
  simd::run_on(-1, kNp, kind, b, verdict);
}

void fast_path_settle(Kind kind, const NpBatch& b, const NpVerdict* verdict, double toi_tolerance,
                      FastSettled* settled, double* toi) {
  simd::run_on(-1, kSettle, kind, b, verdict, toi_target_level(toi_tolerance), settled, toi);
}

bool fast_path_settle_with(int isa, Kind kind, const NpBatch& b, const NpVerdict* verdict,
                           double toi_tolerance, FastSettled* settled, double* toi) {
  return isa >= 0 && simd::run_on(isa, kSettle, kind, b, verdict, toi_target_level(toi_tolerance),
                                  settled, toi);
}

void distance_filter_batch(Kind kind, const NpBatch& b, double thickness, int depth,
                           NpVerdict* verdict) {
  simd::run_on(-1, kDistance, kind, b, thickness, depth, verdict);
}

bool distance_filter_batch_with(int isa, Kind kind, const NpBatch& b, double thickness, int depth,
                                NpVerdict* verdict) {
  return isa >= 0 && simd::run_on(isa, kDistance, kind, b, thickness, depth, verdict);
}

int batch_isa() {
  return simd::widest_isa();
}

bool np_filter_batch_with(int isa, Kind kind, const NpBatch& b, NpVerdict* verdict) {
  return isa >= 0 && simd::run_on(isa, kNp, kind, b, verdict);
}

}  // namespace clothcd::ccd_detail
