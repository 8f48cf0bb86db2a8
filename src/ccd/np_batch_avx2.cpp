// The vector NP filter for avx2 (this file is compiled for that instruction set).
#include "ccd/np_batch_impl.hpp"

namespace clothcd::ccd_detail {
template void NpBlockKernel::operator()<xsimd::avx2>(xsimd::avx2, bool, const NpBlock&,
                                                     unsigned char*) const;
}  // namespace clothcd::ccd_detail
