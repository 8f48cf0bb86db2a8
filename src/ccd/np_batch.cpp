#include "ccd/np_batch.hpp"

// Without xsimd or off x86-64 (CLOTHCD_NP_BATCH_X86 unset) the batch runs the scalar filter.

namespace clothcd::ccd_detail {

#if CLOTHCD_NP_BATCH_X86
void np_filter_batch_sse2(Kind kind, const NpBatch& b, NpVerdict* verdict);
void np_filter_batch_avx2(Kind kind, const NpBatch& b, NpVerdict* verdict);
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

#if CLOTHCD_NP_BATCH_X86
bool has_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2") != 0;
  return yes;
}
#endif

}  // namespace

void np_filter_batch(Kind kind, const NpBatch& b, NpVerdict* verdict) {
#if CLOTHCD_NP_BATCH_X86
  if (has_avx2()) {
    np_filter_batch_avx2(kind, b, verdict);
  } else {
    np_filter_batch_sse2(kind, b, verdict);
  }
#else
  np_filter_batch_scalar(kind, b, verdict);
#endif
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
#endif
    default:
      return false;
  }
}

}  // namespace clothcd::ccd_detail
