// Closest points by candidates: the minimum distance between a point and a triangle (or two
// segments) is reached either in the interior, where the unconstrained solution is valid, or on
// the boundary, which reduces to point-segment distances. Every candidate is a real pair of
// points, so taking the smallest never underestimates, and the boundary candidates alone are
// exact for degenerate or parallel input; the interior candidate is used only where it is valid.

#include "clothcd/ccd/proximity.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace clothcd {

namespace {

void require_finite(std::initializer_list<const Eigen::Vector3d*> points, const char* what) {
  for (const Eigen::Vector3d* p : points) {
    if (!p->allFinite()) throw std::invalid_argument(std::string(what) + ": non-finite input");
  }
}

}  // namespace

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

EdgeEdgeProximity edge_edge_proximity(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                      const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1) {
  require_finite({&ea0, &ea1, &eb0, &eb1}, "edge_edge_proximity");
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

}  // namespace clothcd
