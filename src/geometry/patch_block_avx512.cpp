// patch_block with AVX-512F (called only where the processor has it and FMA): eight triangles a
// batch.
#include <xsimd/xsimd.hpp>
#define PATCH_CONTROLS_NAMESPACE avx512_impl
#include "geometry/patch_controls_impl.hpp"

namespace clothcd::detail {

void patch_block_avx512(const std::array<int, 3>* faces, const int* ids, int count,
                        const Eigen::Vector3d* v0, const Eigen::Vector3d* v1, PatchBlock& out) {
  avx512_impl::patch_block<xsimd::batch<double, xsimd::avx512f>>(faces, ids, count, v0, v1, out);
}

}  // namespace clothcd::detail
