// The vector NP filter for sse2 (this file is compiled for that instruction set).
#include "ccd/np_batch_impl.hpp"

namespace clothcd::ccd_detail {
template void NpBlockKernel::operator()<xsimd::sse2>(xsimd::sse2, bool, const NpBlock&,
                                                     unsigned char*) const;
}  // namespace clothcd::ccd_detail
