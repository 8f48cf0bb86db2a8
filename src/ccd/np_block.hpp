#pragma once
// Internal: a block of CCD queries for the vector NP filter (np_batch.hpp). Kept free of Eigen and
// of anything else with inline code, because the files that compile the filter for a wider
// instruction set include it: an inline function emitted there could be the copy the linker keeps.

namespace clothcd::ccd_detail {

/// Up to kSize queries in structure-of-arrays form: x[point][coordinate][lane], the points in
/// the kernels' order (VF: v, f0, f1, f2 at t0, then at t1; EE: ea0, ea1, eb0, eb1 at t0, then
/// at t1). Lanes past n are ignored.
struct NpBlock {
  static constexpr int kSize = 64;
  alignas(64) double x[8][3][kSize];
  int n = 0;
};

}  // namespace clothcd::ccd_detail
