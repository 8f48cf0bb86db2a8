// triangles_filter_batch and triangle_bound_batch with the SSE2 baseline: two pairs per
// instruction.
#define FACE_BOUNDS_NAMESPACE sse2_impl
#include "ccd/face_batch_impl.hpp"

namespace clothcd::ccd_detail {

void triangles_filter_batch_sse2(const FacePairBatch& b, double thickness, bool* culls,
                                 double* bound_t1) {
  sse2_impl::triangles_filter_batch_impl<xsimd::sse2>(b, thickness, culls, bound_t1);
}

void triangle_bound_batch_sse2(const StaticFacePairBatch& b, double* bound) {
  sse2_impl::triangle_bound_batch_impl<xsimd::sse2>(b, bound);
}

}  // namespace clothcd::ccd_detail
