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

/// The instruction set the batches (these and face_batch.hpp's) run on this processor, in the
/// ids of the *_with functions: the widest it has.
int batch_isa();

/// The distance filter on the queries the NP filter kept: verdict[i] becomes Culled where
/// distance_filter_culls(query i, thickness, depth) holds, for each i < b.size whose verdict is
/// Kept (such queries are finite). Uses the widest vector instructions the processor has; each lane
/// performs the scalar filter's operations in their order (distance_filter.cpp, proximity.cpp),
/// so every verdict is the scalar one.
void distance_filter_batch(Kind kind, const NpBatch& b, double thickness, int depth,
                           NpVerdict* verdict);

/// The same with a fixed instruction set, for tests (as np_filter_batch_with; 0 runs
/// distance_filter_culls per query).
bool distance_filter_batch_with(int isa, Kind kind, const NpBatch& b, double thickness, int depth,
                                NpVerdict* verdict);

/// The depth (ranges of 2^-kSettleLevel of the step) to which fast_path_settle follows the
/// search. A query left over costs the scalar kernel's whole search, and a shallower level leaves
/// many more of them (docs/results/detect_profile.md gives the settle's share of a detection).
inline constexpr int kSettleLevel = 6;

/// What fast_path_settle finds of a query: the zero-thickness kernel's own answer (fast path on,
/// vertex_face_ccd_np_kept, edge_edge_ccd_np_kept), or Run where it would search deeper.
enum class FastSettled : std::uint8_t {
  Run,   ///< not settled: run the kernel
  Miss,  ///< no contact (the kernel's path FastPath)
  Hit,   ///< contact, first at the time given (the kernel's path Certified, the same toi)
};

/// For each query i < b.size whose NP verdict[i] is Kept, the kernel's depth-first search over
/// time ranges (fast_path_solve) truncated at depth kSettleLevel: settled[i] = Miss where it
/// drops every range it examines (the cubic keeping one sign on it, or the contact point
/// provably outside the features over it: inside_over's No); Hit, with toi[i] the kernel's time
/// of impact, where it certifies a range (inside_over's Yes and a sign change of the cubic)
/// before reaching a range it would split below kSettleLevel; in both cases only when it
/// examines at most kFastPathBudget ranges on the way (past it the kernel calls the inclusion
/// solver). Run elsewhere, NP verdicts other than Kept included. `toi_tolerance` is the
/// kernel's (CcdOptions::toi_tolerance).
/// Each lane performs the kernel's own floating-point operations in its order (make_motion's
/// scaling, coplanarity_cubic, np_culls, subdivision_error, halve, one_sign, inside_data,
/// inside_over, first_root_bound), so what it settles is exactly the kernel's answer. The lanes
/// follow the search level by level, all ranges of a level at once; the kernel's depth-first
/// order visits the same ranges up to its answer: the earliest certified range, after every
/// earlier range is dropped.
void fast_path_settle(Kind kind, const NpBatch& b, const NpVerdict* verdict, double toi_tolerance,
                      FastSettled* settled, double* toi);

/// The same with a fixed instruction set, for tests: 0 scalar (the kernel's truncated search per
/// query), 1 SSE2, 2 AVX2, 3 AVX-512. Returns false (and does nothing) when the processor lacks
/// it.
bool fast_path_settle_with(int isa, Kind kind, const NpBatch& b, const NpVerdict* verdict,
                           double toi_tolerance, FastSettled* settled, double* toi);

/// vertex_face_ccd and edge_edge_ccd for a query whose unscaled_np_filter verdict is known to be
/// Kept: the same result, without running that filter again.
CcdResult vertex_face_ccd_np_kept(const VertexFaceQuery& q, const CcdOptions& opt);
CcdResult edge_edge_ccd_np_kept(const EdgeEdgeQuery& q, const CcdOptions& opt);

}  // namespace clothcd::ccd_detail
