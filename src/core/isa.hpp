#pragma once
// Internal: which of the vectorised bodies (ccd's np_batch.hpp and face_batch.hpp, geometry's
// patch_block.hpp) this processor can run, decided once per process, and the call of the chosen
// one. Included only by sources built with CLOTHCD_SIMD_X86 as their module defines it.

namespace clothcd::simd {

#if CLOTHCD_SIMD_X86
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

/// The body run_on(-1, ...) runs on this processor (0 scalar, 1 SSE2, 2 AVX2, 3 AVX-512F).
inline int widest_isa() {
#if CLOTHCD_SIMD_X86
  return has_avx512() ? 3 : (has_avx2() ? 2 : 1);
#else
  return 0;
#endif
}

/// Runs body[isa] (0 scalar, 1 SSE2, 2 AVX2, 3 AVX-512F; -1: the widest the processor has) on
/// `args`; false, running nothing, where the processor or the build lacks it (a null entry).
template <class Fn, class... Args>
bool run_on(int isa, const Fn (&body)[4], Args&&... args) {
#if CLOTHCD_SIMD_X86
  if (isa < 0) isa = widest_isa();
  if ((isa == 2 && !has_avx2()) || (isa == 3 && !has_avx512())) return false;
#else
  if (isa < 0) isa = 0;
#endif
  if (isa > 3 || body[isa] == nullptr) return false;
  body[isa](args...);
  return true;
}

}  // namespace clothcd::simd
