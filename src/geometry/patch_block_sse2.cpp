// patch_block with SSE2 (the x86-64 baseline): two triangles a batch.
#include <xsimd/xsimd.hpp>
#define PATCH_CONTROLS_NAMESPACE sse2_impl
#include "geometry/patch_controls_impl.hpp"

namespace clothcd::detail {

void patch_block_sse2(const std::array<int, 3>* faces, const int* ids, int count,
                      const Eigen::Vector3d* v0, const Eigen::Vector3d* v1, PatchBlock& out) {
  sse2_impl::patch_block<xsimd::batch<double, xsimd::sse2>>(faces, ids, count, v0, v1, out);
}

}  // namespace clothcd::detail
