// The vector NP filter for avx512f (this file is compiled for that instruction set).
#include "ccd/np_batch_impl.hpp"

namespace clothcd::ccd_detail {
template void NpBlockKernel::operator()<xsimd::avx512f>(xsimd::avx512f, bool, const NpBlock&,
                                                        unsigned char*) const;
}  // namespace clothcd::ccd_detail
