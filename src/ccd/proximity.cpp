// Closest points by candidates: the minimum distance between a point and a triangle (or two
// segments) is reached either in the interior, where the unconstrained solution is valid, or on
// the boundary, which reduces to point-segment distances. Every candidate is a real pair of
// points, so taking the smallest never underestimates, and the boundary candidates alone are
// exact for degenerate or parallel input; the interior candidate is used only where it is valid.

#include "clothcd/ccd/proximity.hpp"

#include "ccd/face_bounds.hpp"
#include "distances.hpp"
#include "slack.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <stdexcept>
#include <string>

namespace clothcd {

namespace {

void require_finite(std::initializer_list<const Eigen::Vector3d*> points, const char* what) {
  for (const Eigen::Vector3d* p : points) {
    if (!p->allFinite()) throw std::invalid_argument(std::string(what) + ": non-finite input");
  }
}

// Euclidean gap between the boxes of two point sets (0 where they overlap).
double box_gap(std::initializer_list<const Eigen::Vector3d*> a,
               std::initializer_list<const Eigen::Vector3d*> b) {
  Eigen::Vector3d lo_a = Eigen::Vector3d::Constant(INFINITY), hi_a = -lo_a;
  Eigen::Vector3d lo_b = lo_a, hi_b = hi_a;
  for (const Eigen::Vector3d* p : a) {
    lo_a = lo_a.cwiseMin(*p);
    hi_a = hi_a.cwiseMax(*p);
  }
  for (const Eigen::Vector3d* p : b) {
    lo_b = lo_b.cwiseMin(*p);
    hi_b = hi_b.cwiseMax(*p);
  }
  const Eigen::Vector3d gap = (lo_b - hi_a).cwiseMax(lo_a - hi_b).cwiseMax(0.0);
  return gap.norm();
}

// |w . d| / |w|, or 0 where w is short against |u| |v| (w = u x v): the sine of the angle
// between u and v is then below 1e-3, and w's direction too uncertain for the bound.
double along_normal(const Eigen::Vector3d& u, const Eigen::Vector3d& v, const Eigen::Vector3d& d) {
  const Eigen::Vector3d w = u.cross(v);
  const double w2 = w.squaredNorm();
  if (!(w2 > 1e-6 * u.squaredNorm() * v.squaredNorm())) return 0.0;
  return std::abs(w.dot(d)) / std::sqrt(w2);
}

}  // namespace

namespace ccd_detail {

// The lower bounds less their rounding allowance, input already checked.
double point_triangle_bound(const Eigen::Vector3d& p, const Eigen::Vector3d& f0,
                            const Eigen::Vector3d& f1, const Eigen::Vector3d& f2) {
  const double bound =
      std::max(box_gap({&p}, {&f0, &f1, &f2}), along_normal(f1 - f0, f2 - f0, p - f0));
  return std::max(0.0, bound - coordinate_slack({&p, &f0, &f1, &f2}));
}
double edge_edge_bound(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                       const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  const double bound =
      std::max(box_gap({&ea0, &ea1}, {&eb0, &eb1}), along_normal(ea1 - ea0, eb1 - eb0, eb0 - ea0));
  return std::max(0.0, bound - coordinate_slack({&ea0, &ea1, &eb0, &eb1}));
}

// The closest points, input already checked.
PointTriangleProximity point_triangle_closest(const Eigen::Vector3d& p, const Eigen::Vector3d& f0,
                                              const Eigen::Vector3d& f1,
                                              const Eigen::Vector3d& f2) {
  PointTriangleProximity best;
  best.distance = INFINITY;
  double best2 = INFINITY;  // squared distances first, as in edge_edge_proximity
  const Eigen::Vector3d* v[3] = {&f0, &f1, &f2};
  // Boundary: the three edges.
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const double s = point_segment_parameter(p, *v[i], *v[j]);
    const Eigen::Vector3d c = *v[i] + s * (*v[j] - *v[i]);
    const double d2 = (p - c).squaredNorm();
    if (!(d2 < best2)) continue;
    const double d = std::sqrt(d2);
    if (d < best.distance) {
      best2 = d2;
      best.distance = d;
      best.closest = c;
      best.weights.setZero();
      best.weights[i] = 1 - s;
      best.weights[j] = s;
    }
  }
  // Interior: solve the 2x2 normal equations for p - f0 = a e1 + b e2 (Gram matrix of e1, e2).
  const Eigen::Vector3d e1 = f1 - f0, e2 = f2 - f0, w = p - f0;
  const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
  const double r1 = w.dot(e1), r2 = w.dot(e2);
  const double det = g11 * g22 - g12 * g12;
  // Only a clearly non-degenerate triangle: otherwise the boundary already holds the minimum.
  if (det > 1e-12 * g11 * g22) {
    const double a = (r1 * g22 - r2 * g12) / det;
    const double b = (r2 * g11 - r1 * g12) / det;
    if (a >= 0 && b >= 0 && a + b <= 1) {
      const Eigen::Vector3d c = f0 + a * e1 + b * e2;
      const double d2 = (p - c).squaredNorm();
      const double d = d2 < best2 ? std::sqrt(d2) : INFINITY;
      if (d < best.distance) {
        best.distance = d;
        best.closest = c;
        best.weights = Eigen::Vector3d(1 - a - b, a, b);
      }
    }
  }
  return best;
}

EdgeEdgeProximity edge_edge_closest(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                    const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  EdgeEdgeProximity best;
  best.distance = INFINITY;
  double best2 = INFINITY;
  // Squared distances first: a candidate no nearer than the best cannot replace it, and one
  // that is takes the square root and the same test as before, so the result is bit for bit
  // that of comparing every candidate's distance (sqrt is monotonic).
  auto consider = [&](double s, double t) {
    const Eigen::Vector3d ca = ea0 + s * (ea1 - ea0), cb = eb0 + t * (eb1 - eb0);
    const double d2 = (ca - cb).squaredNorm();
    if (!(d2 < best2)) return;
    const double d = std::sqrt(d2);
    if (d < best.distance) {
      best = EdgeEdgeProximity{d, s, t, ca, cb};
      best2 = d2;
    }
  };
  // Boundary: an endpoint of one segment against the other segment.
  consider(0, point_segment_parameter(ea0, eb0, eb1));
  consider(1, point_segment_parameter(ea1, eb0, eb1));
  consider(point_segment_parameter(eb0, ea0, ea1), 0);
  consider(point_segment_parameter(eb1, ea0, ea1), 1);
  // Interior: the line-line solution when the lines are not (nearly) parallel; clamped, it is
  // still a valid pair of points.
  const Eigen::Vector3d da = ea1 - ea0, db = eb1 - eb0, r = ea0 - eb0;
  const double a = da.dot(da), b = da.dot(db), c = db.dot(db), d = da.dot(r), e = db.dot(r);
  const double den = a * c - b * b;
  if (den > 1e-14 * a * c) {
    const double s = std::clamp((b * e - c * d) / den, 0.0, 1.0);
    const double t = std::clamp((a * e - b * d) / den, 0.0, 1.0);
    consider(s, t);
  }
  return best;
}

double point_triangle_within(const Eigen::Vector3d& p, const Eigen::Vector3d& f0,
                             const Eigen::Vector3d& f1, const Eigen::Vector3d& f2, double limit) {
  const double bound = point_triangle_bound(p, f0, f1, f2);
  return bound > limit ? bound : point_triangle_closest(p, f0, f1, f2).distance;
}

double edge_edge_within(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                        const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1, double limit) {
  const double bound = edge_edge_bound(ea0, ea1, eb0, eb1);
  return bound > limit ? bound : edge_edge_closest(ea0, ea1, eb0, eb1).distance;
}

}  // namespace ccd_detail

double point_triangle_distance_lower_bound(const Eigen::Vector3d& p, const Eigen::Vector3d& f0,
                                           const Eigen::Vector3d& f1, const Eigen::Vector3d& f2) {
  require_finite({&p, &f0, &f1, &f2}, "point_triangle_distance_lower_bound");
  return ccd_detail::point_triangle_bound(p, f0, f1, f2);
}

double edge_edge_distance_lower_bound(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                      const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  require_finite({&ea0, &ea1, &eb0, &eb1}, "edge_edge_distance_lower_bound");
  return ccd_detail::edge_edge_bound(ea0, ea1, eb0, eb1);
}

double triangle_triangle_distance_lower_bound(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1,
                                              const Eigen::Vector3d& a2, const Eigen::Vector3d& b0,
                                              const Eigen::Vector3d& b1,
                                              const Eigen::Vector3d& b2) {
  require_finite({&a0, &a1, &a2, &b0, &b1, &b2}, "triangle_triangle_distance_lower_bound");
  return ccd_detail::triangle_triangle_bound({&a0, &a1, &a2}, {&b0, &b1, &b2});
}

double point_triangle_distance_if_within(const Eigen::Vector3d& p, const Eigen::Vector3d& f0,
                                         const Eigen::Vector3d& f1, const Eigen::Vector3d& f2,
                                         double limit) {
  require_finite({&p, &f0, &f1, &f2}, "point_triangle_distance_if_within");
  return ccd_detail::point_triangle_within(p, f0, f1, f2, limit);
}

double edge_edge_distance_if_within(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                    const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1,
                                    double limit) {
  require_finite({&ea0, &ea1, &eb0, &eb1}, "edge_edge_distance_if_within");
  return ccd_detail::edge_edge_within(ea0, ea1, eb0, eb1, limit);
}

double point_segment_parameter(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                               const Eigen::Vector3d& b) {
  const Eigen::Vector3d e = b - a;
  const double len2 = e.squaredNorm();
  if (!(len2 > 0)) return 0;
  return std::clamp((p - a).dot(e) / len2, 0.0, 1.0);
}

PointTriangleProximity point_triangle_proximity(const Eigen::Vector3d& p, const Eigen::Vector3d& f0,
                                                const Eigen::Vector3d& f1,
                                                const Eigen::Vector3d& f2) {
  require_finite({&p, &f0, &f1, &f2}, "point_triangle_proximity");
  return ccd_detail::point_triangle_closest(p, f0, f1, f2);
}

EdgeEdgeProximity edge_edge_proximity(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                      const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  require_finite({&ea0, &ea1, &eb0, &eb1}, "edge_edge_proximity");
  return ccd_detail::edge_edge_closest(ea0, ea1, eb0, eb1);
}

}  // namespace clothcd
