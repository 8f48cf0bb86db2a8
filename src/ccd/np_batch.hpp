#pragma once
// Internal: the NP filter (unscaled_np_filter) over a batch of queries of one kind held as a
// structure of arrays, several queries per vector instruction. Each lane performs the same
// floating-point operations in the same order as the scalar filter (no contraction, no
// reassociation), so every verdict is the scalar one, bit for bit.

#include <array>
#include <cstdint>

#include "ccd/cubic.hpp"
#include "clothcd/ccd/queries.hpp"

namespace clothcd::ccd_detail {

/// Queries of one kind, gathered for np_filter_batch: coordinate c (0..2) of point p (0..7: the
/// query's four points at t = 0, then at t = 1, in Kind's order) of query i is x[3 * p + c][i].
struct NpBatch {
  static constexpr int kCapacity = 128;  // a multiple of every vector width
  double x[24][kCapacity] = {};
  int size = 0;

  [[nodiscard]] bool full() const { return size == kCapacity; }
  /// Appends a query given by its 8 points (three doubles each).
  void push(const std::array<const double*, 8>& points) {
    for (int p = 0; p < 8; ++p) {
      for (int c = 0; c < 3; ++c)
        x[3 * p + c][size] = points[p][c];
    }
    ++size;
  }
};

/// verdict[i] = unscaled_np_filter of query i of `b`, for i < b.size. Uses the widest vector
/// instructions the processor has (AVX-512, AVX2 or the SSE2 baseline).
void np_filter_batch(Kind kind, const NpBatch& b, NpVerdict* verdict);

/// The same with a fixed instruction set, for tests: 0 scalar (unscaled_np_filter per query),
/// 1 SSE2, 2 AVX2, 3 AVX-512F. Returns false (and does nothing) when the processor
/// lacks it.
bool np_filter_batch_with(int isa, Kind kind, const NpBatch& b, NpVerdict* verdict);

/// The depth (ranges of 2^-kMissLevel of the step) to which fast_path_misses follows the search.
/// On cloth_ball 92 -> 93, of 2.23 M kept queries, depth 4 settles 1.99 M and depth 6 2.09 M
/// (113,855 are hits); each query left over costs the scalar kernel's whole search.
inline constexpr int kMissLevel = 6;

/// For each query i < b.size whose NP verdict[i] is Kept: miss[i] = true where the kernel at
/// zero thickness with the fast path (vertex_face_ccd_np_kept, edge_edge_ccd_np_kept) reports no
/// contact, with path FastPath, by depth kMissLevel of its search: the scaled cubic is not
/// NP-culled, every range the search examines by then is dropped, the cubic keeping one sign
/// on it or the contact point provably outside the features over it (inside_over's No), and
/// those ranges number at most kFastPathBudget (past it the kernel calls the inclusion solver).
/// miss[i] = false elsewhere: run the kernel.
/// Each lane performs the kernel's own floating-point operations in its order (make_motion's
/// scaling, coplanarity_cubic, np_culls, subdivision_error, halve, one_sign, inside_data,
/// inside_over), so a miss is exactly the kernel's verdict.
void fast_path_misses(Kind kind, const NpBatch& b, const NpVerdict* verdict, bool* miss);

/// The same with a fixed instruction set, for tests: 0 scalar (the kernel's functions per
/// query), 1 SSE2, 2 AVX2, 3 AVX-512. Returns false (and does nothing) when the processor lacks
/// it.
bool fast_path_misses_with(int isa, Kind kind, const NpBatch& b, const NpVerdict* verdict,
                           bool* miss);

/// vertex_face_ccd and edge_edge_ccd for a query whose unscaled_np_filter verdict is known to be
/// Kept: the same result, without running that filter again.
CcdResult vertex_face_ccd_np_kept(const VertexFaceQuery& q, const CcdOptions& opt);
CcdResult edge_edge_ccd_np_kept(const EdgeEdgeQuery& q, const CcdOptions& opt);

}  // namespace clothcd::ccd_detail
