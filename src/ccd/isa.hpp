#pragma once
// Internal: which of the vectorised bodies (np_batch.hpp, face_batch.hpp) this processor can run,
// decided once per process.

namespace clothcd::ccd_detail {

#if CLOTHCD_NP_BATCH_X86
inline bool has_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2") != 0;
  return yes;
}
// Eigen's headers require FMA beside AVX-512F, so that body is built with it (never fused).
inline bool has_avx512() {
  static const bool yes =
      __builtin_cpu_supports("avx512f") != 0 && __builtin_cpu_supports("fma") != 0;
  return yes;
}
#endif

}  // namespace clothcd::ccd_detail
