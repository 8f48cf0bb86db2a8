// np_filter_batch, distance_filter_batch and fast_path_settle with AVX-512 (AVX-512F; called only
// where the processor has it and FMA): eight queries per instruction. Compiled with
// -ffp-contract=off: -mfma is there only because Eigen's headers require it beside -mavx512f, and
// no expression is fused.
#define NP_BATCH_NAMESPACE avx512_impl
#include "ccd/distance_batch_impl.hpp"
#include "ccd/np_batch_impl.hpp"

namespace clothcd::ccd_detail {

void np_filter_batch_avx512(Kind kind, const NpBatch& b, NpVerdict* verdict) {
  avx512_impl::np_filter_batch_impl<xsimd::avx512f>(kind, b, verdict);
}

void distance_filter_batch_avx512(Kind kind, const NpBatch& b, double thickness, int depth,
                                  NpVerdict* verdict) {
  avx512_impl::distance_filter_batch_impl<xsimd::avx512f>(kind, b, thickness, depth, verdict);
}

void fast_path_settle_avx512(Kind kind, const NpBatch& b, const NpVerdict* verdict, int target,
                             FastSettled* settled, double* toi) {
  avx512_impl::fast_path_settle_impl<xsimd::avx512f>(kind, b, verdict, target, settled, toi);
}

}  // namespace clothcd::ccd_detail
