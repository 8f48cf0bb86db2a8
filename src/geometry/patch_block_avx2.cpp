// patch_block with AVX2: four triangles a batch.
#include <xsimd/xsimd.hpp>
#define PATCH_CONTROLS_NAMESPACE avx2_impl
#include "geometry/patch_controls_impl.hpp"

namespace clothcd::detail {

void patch_block_avx2(const std::array<int, 3>* faces, const int* ids, int count,
                      const Eigen::Vector3d* v0, const Eigen::Vector3d* v1, PatchBlock& out) {
  avx2_impl::patch_block<xsimd::batch<double, xsimd::avx2>>(faces, ids, count, v0, v1, out);
}

}  // namespace clothcd::detail
