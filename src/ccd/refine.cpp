#include "ccd/refine.hpp"

#include <cmath>

#include "ccd/inclusion.hpp"
#include "ccd/motion.hpp"

namespace clothcd::ccd_detail {

namespace {

struct Search {
  Motion m;
  InclusionParams p;
  double step = 0;
  bool trivial = false;  // contact from the start, as the kernels decide it

  Search(const std::array<const Eigen::Vector3d*, 8>& points, const CcdOptions& opt)
      : m(make_motion(points)) {
    trivial = opt.thickness >= 4 * m.largest;
    p.thickness =
        m.scale > 0 ? opt.thickness * m.scale : std::ldexp(opt.thickness, m.scale_exponent);
    p.tolerance = opt.tolerance * m.extent;
    p.max_boxes = opt.max_boxes;
    // Existence only: the first box that cannot be rejected prunes every other.
    p.toi_tolerance = 1.0;
    // The solver's box bounds must be dyadic: the points searched lie on the tolerance's grid.
    step = std::ldexp(1.0, std::ilogb(std::max(opt.toi_tolerance, 0x1p-40)));
  }
  [[nodiscard]] double down(double t) const { return std::floor(t / step) * step; }
  [[nodiscard]] double up(double t) const { return std::min(1.0, std::ceil(t / step) * step); }
  // Whether [lo, hi] (grid points) holds a box the solver cannot reject.
  [[nodiscard]] bool touches(Kind kind, double lo, double hi) {
    if (trivial) return true;
    p.t_lo = lo;
    p.t_hi = hi;
    return inclusion_solve(kind, m, p).hit;
  }
};

double refine(Kind kind, const std::array<const Eigen::Vector3d*, 8>& points, const CcdOptions& opt,
              double lo, double hi) {
  Search s(points, opt);
  if (s.trivial) return lo;
  lo = s.down(lo);
  hi = s.up(hi);
  while (hi - lo > opt.toi_tolerance) {
    const double mid = lo + std::floor((hi - lo) / (2 * s.step)) * s.step;
    if (mid <= lo || mid >= hi) break;
    if (s.touches(kind, lo, mid)) {
      hi = mid;
    } else {
      lo = mid;
    }
  }
  return lo;
}

bool may_touch(Kind kind, const std::array<const Eigen::Vector3d*, 8>& points,
               const CcdOptions& opt, double lo, double hi) {
  Search s(points, opt);
  return s.touches(kind, s.down(lo), s.up(hi));
}

std::array<const Eigen::Vector3d*, 8> points_of(const VertexFaceQuery& q) {
  return {&q.v_t0, &q.f0_t0, &q.f1_t0, &q.f2_t0, &q.v_t1, &q.f0_t1, &q.f1_t1, &q.f2_t1};
}
std::array<const Eigen::Vector3d*, 8> points_of(const EdgeEdgeQuery& q) {
  return {&q.ea0_t0, &q.ea1_t0, &q.eb0_t0, &q.eb1_t0, &q.ea0_t1, &q.ea1_t1, &q.eb0_t1, &q.eb1_t1};
}

}  // namespace

double refine_time_of_impact(const VertexFaceQuery& q, const CcdOptions& opt, double lo,
                             double hi) {
  return refine(Kind::VertexFace, points_of(q), opt, lo, hi);
}
double refine_time_of_impact(const EdgeEdgeQuery& q, const CcdOptions& opt, double lo, double hi) {
  return refine(Kind::EdgeEdge, points_of(q), opt, lo, hi);
}
bool may_touch(const VertexFaceQuery& q, const CcdOptions& opt, double lo, double hi) {
  return may_touch(Kind::VertexFace, points_of(q), opt, lo, hi);
}
bool may_touch(const EdgeEdgeQuery& q, const CcdOptions& opt, double lo, double hi) {
  return may_touch(Kind::EdgeEdge, points_of(q), opt, lo, hi);
}

}  // namespace clothcd::ccd_detail
