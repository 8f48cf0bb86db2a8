#pragma once
// Internal: the per-triangle part of patch_ccd_cone (leaf_cone.cpp), a block of triangles at a
// time in lanes: the widest body the processor runs (patch_block_*.cpp), or the scalar one.

#include <Eigen/Core>

#include <array>

namespace clothcd::detail {

/// Up to kLanes triangles' Bernstein control vectors n0, nx, n1 (index 0, 1, 2), their squared
/// lengths q and unit directions n / sqrt(q), the squared error ratios of ccd_leaf_cone's bounds
/// for n0, n1 and nx (r0, r1, rx), and whether every squared edge and control length lies in
/// [1e-140, 1e140] (in_range 1, else 0), where those bounds hold as computed. Structure of arrays.
struct alignas(64) PatchBlock {
  static constexpr int kLanes = 8;
  double n[3][3][kLanes], unit[3][3][kLanes], q[3][kLanes];
  double r0[kLanes], r1[kLanes], rx[kLanes], in_range[kLanes];
};

/// Fills lanes [0, count) of `out` for triangles faces[ids[0, count)], count in [1, kLanes],
/// moving from positions v0 to v1; every body gives the same bits.
void patch_block(const std::array<int, 3>* faces, const int* ids, int count,
                 const Eigen::Vector3d* v0, const Eigen::Vector3d* v1, PatchBlock& out);
/// The same on body `isa` (0 scalar, 1 SSE2, 2 AVX2, 3 AVX-512F); false, running nothing, where
/// the processor or the build lacks it. For tests.
bool patch_block_with(int isa, const std::array<int, 3>* faces, const int* ids, int count,
                      const Eigen::Vector3d* v0, const Eigen::Vector3d* v1, PatchBlock& out);

}  // namespace clothcd::detail
