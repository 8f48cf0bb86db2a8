#pragma once
// Internal: a kernel's time of impact refined by bisection (the earliest-impact query's last
// step). The kernels refine a hit's time within their own search, which at a tight tolerance
// must resolve the whole front of the contact region, exhausting its budget where a thickness
// makes that region wide. Here each step only asks whether [lo, mid] holds a box the inclusion
// solver cannot reject: the first such box answers yes, a full rejection answers no.

#include "ccd/inclusion.hpp"
#include "clothcd/ccd/queries.hpp"

namespace clothcd::ccd_detail {

/// For a query with no contact in [0, lo) (lo a kernel's time of impact, or 0) and a box the
/// inclusion solver cannot reject starting by hi: a time t in [lo, hi] with no contact in
/// [0, t), within opt.toi_tolerance of the start of such a box (t = lo where the bisection
/// cannot go on: an exhausted budget counts as a box). lo and hi in [0, 1], lo <= hi.
/// opt.thickness and opt.tolerance as for the kernels.
[[nodiscard]] double refine_time_of_impact(const VertexFaceQuery& q, const CcdOptions& opt,
                                           double lo, double hi);
[[nodiscard]] double refine_time_of_impact(const EdgeEdgeQuery& q, const CcdOptions& opt, double lo,
                                           double hi);

/// Whether [lo, hi] (widened outwards to opt.toi_tolerance's dyadic grid) holds a box the
/// inclusion solver cannot reject (or the search ran out of boxes): false proves that the
/// features stay farther apart than opt.thickness over [lo, hi].
[[nodiscard]] bool may_touch(const VertexFaceQuery& q, const CcdOptions& opt, double lo, double hi);
[[nodiscard]] bool may_touch(const EdgeEdgeQuery& q, const CcdOptions& opt, double lo, double hi);

/// The distance a kernel hit certifies (queries.hpp): sqrt(3) (opt.thickness + opt.tolerance L),
/// L the query's extent (largest coordinate range of its eight points), widened by the solver's
/// rounding bound (the same reach bounded_inclusion_solve uses). A pair that stays farther apart
/// than this over [lo, hi] has no hit there.
[[nodiscard]] double certified_distance(const VertexFaceQuery& q, const CcdOptions& opt);
[[nodiscard]] double certified_distance(const EdgeEdgeQuery& q, const CcdOptions& opt);

/// true proves that the features stay farther apart than `distance` over [0, hi]: the direction n
/// from the closest point of the second feature to that of the first at t0 separates every
/// corner of their difference (a vertex minus a face corner, an edge end minus an edge end) by
/// more than `distance` at t = 0 and at t = hi, with an allowance for rounding. The features'
/// difference at any time and parameters is a combination of those corners that is linear in
/// each parameter and in t, so its component along n is smallest at one of them. At t0 that holds
/// for the exact closest points (they give the shortest point of a convex set); it fails, and the
/// test says nothing, where the motion closes the gap along n within [0, hi]. Cheap (a few dot
/// products), and it settles the near-touching pairs that slide past each other (stitched
/// seams, resting contact), which cost may_touch's search the most.
[[nodiscard]] bool stay_apart(const VertexFaceQuery& q, double hi, double distance);
[[nodiscard]] bool stay_apart(const EdgeEdgeQuery& q, double hi, double distance);

/// inclusion_solve(kind, m, p) with a way out for the searches that run long: past a quick budget
/// of boxes, stay_apart on p's time range (at the distance a hit box certifies); a pair proven
/// apart has no hit, and any other goes on with the whole budget from the start. The same
/// outcome as inclusion_solve wherever that finds a hit box or rejects every box; where its
/// budget would run out (reporting its earliest open time as a hit), a pair proven apart is no
/// hit instead. `boxes` counts every box examined.
[[nodiscard]] InclusionOutcome bounded_inclusion_solve(Kind kind, const Motion& m,
                                                       const InclusionParams& p);

}  // namespace clothcd::ccd_detail
