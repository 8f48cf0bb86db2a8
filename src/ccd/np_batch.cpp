#include "ccd/np_batch.hpp"

#include <array>

#include "ccd/cubic.hpp"

#if defined(CLOTHCD_SIMD_X86)
#include "ccd/np_batch_impl.hpp"

namespace clothcd::ccd_detail {
// Defined in np_batch_<isa>.cpp, each compiled for its instruction set.
extern template void NpBlockKernel::operator()<xsimd::sse2>(xsimd::sse2, bool, const NpBlock&,
                                                            unsigned char*) const;
extern template void NpBlockKernel::operator()<xsimd::avx2>(xsimd::avx2, bool, const NpBlock&,
                                                            unsigned char*) const;
extern template void NpBlockKernel::operator()<xsimd::avx512f>(xsimd::avx512f, bool, const NpBlock&,
                                                               unsigned char*) const;
}  // namespace clothcd::ccd_detail
#endif

namespace clothcd::ccd_detail {

namespace {

#if !defined(CLOTHCD_SIMD_X86)
// One query at a time through the scalar filter: the reference the vector code matches, and the
// path of builds without the x86 vector files.
void scalar_block(Kind kind, const NpBlock& b, std::uint8_t* culled) {
  for (int i = 0; i < b.n; ++i) {
    std::array<Eigen::Vector3d, 8> p;
    std::array<const Eigen::Vector3d*, 8> ptr;
    for (int k = 0; k < 8; ++k) {
      p[k] = {b.x[k][0][i], b.x[k][1][i], b.x[k][2][i]};
      ptr[k] = &p[k];
    }
    culled[i] = unscaled_np_filter(kind, ptr) == NpVerdict::culled ? 1 : 0;
  }
}
#endif

#if defined(CLOTHCD_SIMD_X86)
// The compiler's CPU check (it also asks the OS whether the wider registers are enabled).
NpIsa detect_best() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return NpIsa::avx512;
  if (__builtin_cpu_supports("avx2")) return NpIsa::avx2;
  return NpIsa::sse2;
}
#endif

}  // namespace

bool np_isa_available(NpIsa isa) {
#if defined(CLOTHCD_SIMD_X86)
  static const NpIsa best = detect_best();
  return isa == NpIsa::best || static_cast<int>(isa) <= static_cast<int>(best);
#else
  return isa == NpIsa::best;
#endif
}

void np_filter_block(Kind kind, const NpBlock& b, std::uint8_t* culled, NpIsa isa) {
#if defined(CLOTHCD_SIMD_X86)
  static const NpIsa best = detect_best();
  if (isa == NpIsa::best) isa = best;
  switch (isa) {
    case NpIsa::avx512:
      NpBlockKernel{}(xsimd::avx512f{}, kind == Kind::vertex_face, b, culled);
      return;
    case NpIsa::avx2:
      NpBlockKernel{}(xsimd::avx2{}, kind == Kind::vertex_face, b, culled);
      return;
    default:
      NpBlockKernel{}(xsimd::sse2{}, kind == Kind::vertex_face, b, culled);
      return;
  }
#else
  (void)isa;
  scalar_block(kind, b, culled);
#endif
}

}  // namespace clothcd::ccd_detail
