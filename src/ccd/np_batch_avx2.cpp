// np_filter_batch, distance_filter_batch and fast_path_settle with AVX2 (compiled with -mavx2,
// without FMA; called only where the processor has AVX2).
#define NP_BATCH_NAMESPACE avx2_impl
#include "ccd/distance_batch_impl.hpp"
#include "ccd/np_batch_impl.hpp"

namespace clothcd::ccd_detail {

void np_filter_batch_avx2(Kind kind, const NpBatch& b, NpVerdict* verdict) {
  avx2_impl::np_filter_batch_impl<xsimd::avx2>(kind, b, verdict);
}

void distance_filter_batch_avx2(Kind kind, const NpBatch& b, double thickness, int depth,
                                NpVerdict* verdict) {
  avx2_impl::distance_filter_batch_impl<xsimd::avx2>(kind, b, thickness, depth, verdict);
}

void fast_path_settle_avx2(Kind kind, const NpBatch& b, const NpVerdict* verdict, int target,
                           FastSettled* settled, double* toi) {
  avx2_impl::fast_path_settle_impl<xsimd::avx2>(kind, b, verdict, target, settled, toi);
}

}  // namespace clothcd::ccd_detail
