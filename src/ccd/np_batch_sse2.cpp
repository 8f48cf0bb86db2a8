// np_filter_batch, distance_filter_batch and fast_path_settle on the SSE2 baseline (every x86-64
// processor).
#define NP_BATCH_NAMESPACE sse2_impl
#include "ccd/distance_batch_impl.hpp"
#include "ccd/np_batch_impl.hpp"

namespace clothcd::ccd_detail {

void np_filter_batch_sse2(Kind kind, const NpBatch& b, NpVerdict* verdict) {
  sse2_impl::np_filter_batch_impl<xsimd::sse2>(kind, b, verdict);
}

void distance_filter_batch_sse2(Kind kind, const NpBatch& b, double thickness, int depth,
                                NpVerdict* verdict) {
  sse2_impl::distance_filter_batch_impl<xsimd::sse2>(kind, b, thickness, depth, verdict);
}

void fast_path_settle_sse2(Kind kind, const NpBatch& b, const NpVerdict* verdict, int target,
                           FastSettled* settled, double* toi) {
  sse2_impl::fast_path_settle_impl<xsimd::sse2>(kind, b, verdict, target, settled, toi);
}

}  // namespace clothcd::ccd_detail
