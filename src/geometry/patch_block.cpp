// The dispatch of patch_block: the widest body the processor has (patch_block_*.cpp), or the
// scalar one without xsimd or off x86-64 (CLOTHCD_SIMD_X86 unset).
#include "geometry/patch_block.hpp"

#include "core/isa.hpp"
#define PATCH_CONTROLS_NAMESPACE scalar_impl
#include "geometry/patch_controls_impl.hpp"

namespace clothcd::detail {

using PatchBody = void (*)(const std::array<int, 3>*, const int*, int, const Eigen::Vector3d*,
                           const Eigen::Vector3d*, PatchBlock&);

#if CLOTHCD_SIMD_X86
void patch_block_sse2(const std::array<int, 3>*, const int*, int, const Eigen::Vector3d*,
                      const Eigen::Vector3d*, PatchBlock&);
void patch_block_avx2(const std::array<int, 3>*, const int*, int, const Eigen::Vector3d*,
                      const Eigen::Vector3d*, PatchBlock&);
void patch_block_avx512(const std::array<int, 3>*, const int*, int, const Eigen::Vector3d*,
                        const Eigen::Vector3d*, PatchBlock&);
#endif

namespace {
#if CLOTHCD_SIMD_X86
constexpr PatchBody kBodies[4] = {scalar_impl::patch_block<double>, patch_block_sse2,
                                  patch_block_avx2, patch_block_avx512};
#else
constexpr PatchBody kBodies[4] = {scalar_impl::patch_block<double>, nullptr, nullptr, nullptr};
#endif
}  // namespace

void patch_block(const std::array<int, 3>* faces, const int* ids, int count,
                 const Eigen::Vector3d* v0, const Eigen::Vector3d* v1, PatchBlock& out) {
  static const PatchBody body = kBodies[simd::widest_isa()];
  body(faces, ids, count, v0, v1, out);
}

bool patch_block_with(int isa, const std::array<int, 3>* faces, const int* ids, int count,
                      const Eigen::Vector3d* v0, const Eigen::Vector3d* v1, PatchBlock& out) {
  return isa >= 0 && simd::run_on(isa, kBodies, faces, ids, count, v0, v1, out);
}

}  // namespace clothcd::detail
