#include "ccd/refine.hpp"

#include <cmath>

#include "ccd/inclusion.hpp"
#include "ccd/motion.hpp"

namespace clothcd::ccd_detail {

namespace {

double refine(Kind kind, const std::array<const Eigen::Vector3d*, 8>& points, const CcdOptions& opt,
              double lo, double hi) {
  const Motion m = make_motion(points);
  // Contact from the start (as the kernels decide it): nothing to refine.
  if (opt.thickness >= 4 * m.largest) return lo;
  InclusionParams p;
  p.thickness = m.scale > 0 ? opt.thickness * m.scale : std::ldexp(opt.thickness, m.scale_exponent);
  p.tolerance = opt.tolerance * m.extent;
  p.max_boxes = opt.max_boxes;
  // The bisection's points are dyadic, as the solver's box bounds must be: start from the
  // dyadic range of the tolerance's grid that holds [lo, hi].
  const double step = std::ldexp(1.0, std::ilogb(std::max(opt.toi_tolerance, 0x1p-40)));
  lo = std::floor(lo / step) * step;
  hi = std::min(1.0, std::ceil(hi / step) * step);
  while (hi - lo > opt.toi_tolerance) {
    const double mid = lo + std::floor((hi - lo) / (2 * step)) * step;
    if (mid <= lo || mid >= hi) break;
    p.t_lo = lo;
    p.t_hi = mid;
    // Existence only: the first box that cannot be rejected prunes every other.
    p.toi_tolerance = 1.0;
    const InclusionOutcome o = inclusion_solve(kind, m, p);
    if (o.hit) {
      hi = mid;
    } else {
      lo = mid;
    }
  }
  return lo;
}

}  // namespace

double refine_time_of_impact(const VertexFaceQuery& q, const CcdOptions& opt, double lo,
                             double hi) {
  return refine(Kind::VertexFace,
                {&q.v_t0, &q.f0_t0, &q.f1_t0, &q.f2_t0, &q.v_t1, &q.f0_t1, &q.f1_t1, &q.f2_t1}, opt,
                lo, hi);
}

double refine_time_of_impact(const EdgeEdgeQuery& q, const CcdOptions& opt, double lo, double hi) {
  return refine(
      Kind::EdgeEdge,
      {&q.ea0_t0, &q.ea1_t0, &q.eb0_t0, &q.eb1_t0, &q.ea0_t1, &q.ea1_t1, &q.eb0_t1, &q.eb1_t1}, opt,
      lo, hi);
}

}  // namespace clothcd::ccd_detail
