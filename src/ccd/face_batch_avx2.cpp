// triangles_filter_batch and triangle_bound_batch with AVX2 (called only where the processor has
// it): four pairs per instruction.
#define FACE_BOUNDS_NAMESPACE avx2_impl
#include "ccd/face_batch_impl.hpp"

namespace clothcd::ccd_detail {

void triangles_filter_batch_avx2(const FacePairBatch& b, double thickness, bool* culls,
                                 double* bound_t1) {
  avx2_impl::triangles_filter_batch_impl<xsimd::avx2>(b, thickness, culls, bound_t1);
}

void triangle_bound_batch_avx2(const StaticFacePairBatch& b, double* bound) {
  avx2_impl::triangle_bound_batch_impl<xsimd::avx2>(b, bound);
}

}  // namespace clothcd::ccd_detail
