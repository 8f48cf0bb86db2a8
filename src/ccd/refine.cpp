#include "ccd/refine.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "ccd/inclusion.hpp"
#include "ccd/motion.hpp"
#include "clothcd/ccd/proximity.hpp"

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
    return bounded_inclusion_solve(kind, m, p).hit;
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

// The largest coordinate range (extent) and the largest |coordinate| of the points.
std::pair<double, double> extent_and_magnitude(const std::array<const Eigen::Vector3d*, 8>& p) {
  Eigen::Vector3d lo = *p[0], hi = *p[0];
  double m = 0;
  for (const Eigen::Vector3d* x : p) {
    lo = lo.cwiseMin(*x);
    hi = hi.cwiseMax(*x);
    m = std::max(m, x->cwiseAbs().maxCoeff());
  }
  return {(hi - lo).maxCoeff(), m};
}

// A query's difference corners (first[k] - second[k], each point at t0 and t1) and the
// separation of its features at a time (the closest point of the first minus that of the second).
template <std::size_t N, class Separation>
struct Corners {
  std::array<const Eigen::Vector3d*, N> a0, a1, b0, b1;
  Separation separation;  // separation(t)
  double need = 0;        // the distance to stay beyond, with the rounding allowance

  // Whether n keeps every corner farther than `need` at lo and at hi.
  [[nodiscard]] bool apart_along(const Eigen::Vector3d& n, double lo, double hi) const {
    for (std::size_t k = 0; k < N; ++k) {
      for (const double t : {lo, hi}) {
        const Eigen::Vector3d a = *a0[k] + t * (*a1[k] - *a0[k]);
        const Eigen::Vector3d b = *b0[k] + t * (*b1[k] - *b0[k]);
        if (!(n.dot(a - b) > need)) return false;
      }
    }
    return true;
  }
  // Whether one of the directions the separation gives at the middle of [lo, hi] keeps every
  // corner apart over it; otherwise the halves, down to `depth` more levels.
  [[nodiscard]] bool apart(double lo, double hi, int depth) const {
    const double mid = 0.5 * (lo + hi);
    const std::array<Eigen::Vector3d, 3> dirs = separation(mid);
    for (const Eigen::Vector3d& d : dirs) {
      const double len = d.norm();
      if (len > 0 && std::isfinite(len) && apart_along(d / len, lo, hi)) return true;
    }
    return depth > 0 && mid > lo && mid < hi && apart(lo, mid, depth - 1) &&
           apart(mid, hi, depth - 1);
  }
};

// Directions to try for a separation p between features whose own directions are u and w (unit
// or zero): p itself, which separates exactly at the exact closest points, and p without its
// components along u and along w: where the features are nearly parallel the computed closest
// points can slide along them, tilting p by more than the gap allows.
std::array<Eigen::Vector3d, 3> directions(const Eigen::Vector3d& p, const Eigen::Vector3d& u,
                                          const Eigen::Vector3d& w) {
  return {p, p - p.dot(u) * u, p - p.dot(w) * w};
}
Eigen::Vector3d unit(const Eigen::Vector3d& x) {
  const double n = x.norm();
  return n > 0 && std::isfinite(n) ? Eigen::Vector3d(x / n) : Eigen::Vector3d::Zero();
}

// Each corner's component along n is computed with an error below 64 u max|x| (u the unit
// roundoff: the interpolation, the difference and the dot product); the relative term covers
// |n| != 1.
double needed(double distance, double magnitude) {
  return distance * (1 + 1e-12) + 128 * DBL_EPSILON * magnitude + DBL_MIN;
}

// Halvings of [0, hi] stay_apart tries: up to 2^kApartDepth directions, each a few hundred
// instructions, against the thousands of boxes may_touch can take on such a pair.
constexpr int kApartDepth = 5;

// The boxes a search may take before stay_apart is tried on its range (bounded_inclusion_solve):
// most searches end within a few dozen; those that run on are mostly tiling the near-contact set
// of two nearly parallel features.
constexpr std::uint32_t kQuickBoxes = 1024;

// The distance within which a box the inclusion solver reports as a hit lies: the box is
// narrower than the tolerance on every axis (or than 16 err, below which the rounding noise
// keeps it) and overlaps the thickness, each computed corner value within err of the exact one.
// `tolerance` absolute, err from the largest |coordinate|, all in one unit (scaled or not).
double hit_reach(double thickness, double tolerance, double max_abs) {
  const double err = corner_error_bound(max_abs);
  return std::sqrt(3.0) * (thickness + 3 * err + std::max(tolerance, 16 * err)) * (1 + 1e-9);
}

Eigen::Vector3d at(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, double t) {
  return x0 + t * (x1 - x0);
}

// stay_apart over [lo, hi] on a query's points in points_of's order.
bool apart_over(Kind kind, const std::array<const Eigen::Vector3d*, 8>& x, double lo, double hi,
                double distance) {
  const double need = needed(distance, extent_and_magnitude(x).second);
  if (kind == Kind::VertexFace) {
    const auto separation = [&](double t) {
      const Eigen::Vector3d v = at(*x[0], *x[4], t), f0 = at(*x[1], *x[5], t),
                            f1 = at(*x[2], *x[6], t), f2 = at(*x[3], *x[7], t);
      const Eigen::Vector3d p = v - point_triangle_proximity(v, f0, f1, f2).closest;
      // The face's normal, towards the vertex, in place of the components along two edges.
      Eigen::Vector3d normal = unit((f1 - f0).cross(f2 - f0));
      if (normal.dot(p) < 0) normal = -normal;
      return std::array<Eigen::Vector3d, 3>{p, normal,
                                            directions(p, unit(f1 - f0), unit(f2 - f0))[2]};
    };
    const Corners<3, decltype(separation)> c{{x[0], x[0], x[0]}, {x[4], x[4], x[4]},
                                             {x[1], x[2], x[3]}, {x[5], x[6], x[7]},
                                             separation,         need};
    return c.apart(lo, hi, kApartDepth);
  }
  const auto separation = [&](double t) {
    const Eigen::Vector3d a0 = at(*x[0], *x[4], t), a1 = at(*x[1], *x[5], t),
                          b0 = at(*x[2], *x[6], t), b1 = at(*x[3], *x[7], t);
    const EdgeEdgeProximity e = edge_edge_proximity(a0, a1, b0, b1);
    return directions(e.closest_a - e.closest_b, unit(a1 - a0), unit(b1 - b0));
  };
  const Corners<4, decltype(separation)> c{{x[0], x[0], x[1], x[1]},
                                           {x[4], x[4], x[5], x[5]},
                                           {x[2], x[3], x[2], x[3]},
                                           {x[6], x[7], x[6], x[7]},
                                           separation,
                                           need};
  return c.apart(lo, hi, kApartDepth);
}

}  // namespace

double certified_distance(const VertexFaceQuery& q, const CcdOptions& opt) {
  const auto [extent, magnitude] = extent_and_magnitude(points_of(q));
  return hit_reach(opt.thickness, opt.tolerance * extent, magnitude);
}
double certified_distance(const EdgeEdgeQuery& q, const CcdOptions& opt) {
  const auto [extent, magnitude] = extent_and_magnitude(points_of(q));
  return hit_reach(opt.thickness, opt.tolerance * extent, magnitude);
}

bool stay_apart(const VertexFaceQuery& q, double hi, double distance) {
  return apart_over(Kind::VertexFace, points_of(q), 0.0, hi, distance);
}
bool stay_apart(const EdgeEdgeQuery& q, double hi, double distance) {
  return apart_over(Kind::EdgeEdge, points_of(q), 0.0, hi, distance);
}

InclusionOutcome bounded_inclusion_solve(Kind kind, const Motion& m, const InclusionParams& p) {
  if (p.max_boxes <= kQuickBoxes) return inclusion_solve(kind, m, p);
  InclusionParams quick = p;
  quick.max_boxes = kQuickBoxes;
  // The same search as with the whole budget while it stays within the quick one.
  const InclusionOutcome first = inclusion_solve(kind, m, quick);
  if (first.boxes <= kQuickBoxes) return first;
  // A pair proven farther apart than a hit box can be over the range has no hit in it.
  const double reach = hit_reach(p.thickness, p.tolerance, m.max_abs.maxCoeff());
  const std::array<const Eigen::Vector3d*, 8> x = {&m.x0[0], &m.x0[1], &m.x0[2], &m.x0[3],
                                                   &m.x1[0], &m.x1[1], &m.x1[2], &m.x1[3]};
  if (apart_over(kind, x, p.t_lo, p.t_hi, reach)) {
    InclusionOutcome none;
    none.boxes = first.boxes;
    return none;
  }
  InclusionOutcome whole = inclusion_solve(kind, m, p);
  whole.boxes += first.boxes;
  return whole;
}

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
