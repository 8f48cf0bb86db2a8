#pragma once
// Internal: a kernel's time of impact refined by bisection (the earliest-impact query's last
// step). The kernels refine a hit's time within their own search, which at a tight tolerance
// must resolve the whole front of the contact region, exhausting its budget where a thickness
// makes that region wide. Here each step only asks whether [lo, mid] holds a box the inclusion
// solver cannot reject: the first such box answers yes, a full rejection answers no.

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

}  // namespace clothcd::ccd_detail
