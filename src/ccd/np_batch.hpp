#pragma once
// Internal: the NP filter over a block of queries at once, on SIMD vectors (xsimd, the widest
// instruction set the CPU has, chosen at run time), for the detector's narrow phase.
//
// Exactness: every lane performs the same IEEE-754 double operations, in the same order, as the
// scalar filter (unscaled_np_filter: differences, cross and dot products, the error bound eta,
// the range test on A), with round-to-nearest and no fused multiply-add (these files and cubic.cpp
// are compiled with -ffp-contract=off). Every intermediate is therefore bit-identical to the
// scalar one, and so is the verdict: a lane is culled exactly when unscaled_np_filter returns
// `culled` for that query. The vector path decides nothing the scalar path would not; the lanes
// it keeps (kept or undecided) go on to the full scalar kernel.

#include <cstdint>

#include "ccd/motion.hpp"
#include "ccd/np_block.hpp"
#include "clothcd/ccd/queries.hpp"

namespace clothcd::ccd_detail {

/// Instruction sets of the vector filter (`best`: the widest the CPU supports).
enum class NpIsa { best, sse2, avx2, avx512 };

/// Whether this build and CPU can run `isa` (`best` always can).
bool np_isa_available(NpIsa isa);

/// culled[i] = 1 when unscaled_np_filter(kind, query i) == culled, else 0, for i < b.n.
void np_filter_block(Kind kind, const NpBlock& b, std::uint8_t* culled, NpIsa isa = NpIsa::best);

/// The public kernels minus their leading unscaled NP filter: the same result as
/// vertex_face_ccd / edge_edge_ccd for a query that filter does not cull.
CcdResult vertex_face_ccd_unfiltered(const VertexFaceQuery& q, const CcdOptions& opt);
CcdResult edge_edge_ccd_unfiltered(const EdgeEdgeQuery& q, const CcdOptions& opt);

}  // namespace clothcd::ccd_detail
