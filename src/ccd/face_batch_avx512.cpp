// triangles_filter_batch and triangle_bound_batch with AVX-512 (AVX-512F; called only where the
// processor has it and FMA): eight pairs per instruction. -mfma is there only because Eigen's
// headers require it beside -mavx512f; no expression is fused (-ffp-contract=off).
#define FACE_BOUNDS_NAMESPACE avx512_impl
#include "ccd/face_batch_impl.hpp"

namespace clothcd::ccd_detail {

void triangles_filter_batch_avx512(const FacePairBatch& b, double thickness, bool* culls,
                                   double* bound_t1) {
  avx512_impl::triangles_filter_batch_impl<xsimd::avx512f>(b, thickness, culls, bound_t1);
}

void triangle_bound_batch_avx512(const StaticFacePairBatch& b, double* bound) {
  avx512_impl::triangle_bound_batch_impl<xsimd::avx512f>(b, bound);
}

}  // namespace clothcd::ccd_detail
