// Distance filter: a lower bound on the features' distance over a linear motion.
#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <stdexcept>

#include "ccd/face_bounds.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/ccd/queries.hpp"
#include "distances.hpp"
#include "slack.hpp"

namespace clothcd {
namespace {

using Vec3 = Eigen::Vector3d;

double largest_relative_move(std::initializer_list<Vec3> a, std::initializer_list<Vec3> b) {
  double d = 0.0;
  for (const Vec3& x : a) {
    for (const Vec3& y : b)
      d = std::max(d, (x - y).squaredNorm());
  }
  return std::sqrt(d);
}

bool culls(double d0, double d1, double move, double thickness, double eps) {
  const double bound = 0.5 * (d0 + d1 - move);
  return std::isfinite(bound) && bound > thickness + eps;
}

// The bound on [ta, tb] (distances da, db at its ends), bisected up to `depth` times where it
// fails: the distance is Lipschitz with constant `move` on any part of the step, so each half
// needs only its own end distances. `dist(t)` is the distance at time t.
template <class Dist>
bool culls_on(double ta, double tb, double da, double db, double move, double thickness, double eps,
              int depth, Dist&& dist) {
  if (culls(da, db, move * (tb - ta), thickness, eps)) return true;
  if (depth <= 0 || !(std::min(da, db) > thickness + eps)) return false;
  const double tm = 0.5 * (ta + tb);
  const double dm = dist(tm);
  return culls_on(ta, tm, da, dm, move, thickness, eps, depth - 1, dist) &&
         culls_on(tm, tb, dm, db, move, thickness, eps, depth - 1, dist);
}

Vec3 at(const Vec3& x0, const Vec3& x1, double t) {
  return x0 + t * (x1 - x0);
}

// A query's four points at t0 and at t1, in the order of the distance functions' arguments, and
// what tells the two kinds apart: the distance, its lower bound and the largest relative move.
using Points = std::array<Vec3, 4>;
Points ends(const VertexFaceQuery& q, bool t1) {
  return t1 ? Points{q.v_t1, q.f0_t1, q.f1_t1, q.f2_t1} : Points{q.v_t0, q.f0_t0, q.f1_t0, q.f2_t0};
}
Points ends(const EdgeEdgeQuery& q, bool t1) {
  return t1 ? Points{q.ea0_t1, q.ea1_t1, q.eb0_t1, q.eb1_t1}
            : Points{q.ea0_t0, q.ea1_t0, q.eb0_t0, q.eb1_t0};
}
double distance(const VertexFaceQuery&, const Points& p) {
  return ccd_detail::point_triangle_closest(p[0], p[1], p[2], p[3]).distance;
}
double distance(const EdgeEdgeQuery&, const Points& p) {
  return ccd_detail::edge_edge_closest(p[0], p[1], p[2], p[3]).distance;
}
double lower_bound(const VertexFaceQuery&, const Points& p) {
  return ccd_detail::point_triangle_bound(p[0], p[1], p[2], p[3]);
}
double lower_bound(const EdgeEdgeQuery&, const Points& p) {
  return ccd_detail::edge_edge_bound(p[0], p[1], p[2], p[3]);
}
double move(const VertexFaceQuery& q) {
  return largest_relative_move({q.v_t1 - q.v_t0},
                               {q.f0_t1 - q.f0_t0, q.f1_t1 - q.f1_t0, q.f2_t1 - q.f2_t0});
}
double move(const EdgeEdgeQuery& q) {
  return largest_relative_move({q.ea0_t1 - q.ea0_t0, q.ea1_t1 - q.ea1_t0},
                               {q.eb0_t1 - q.eb0_t0, q.eb1_t1 - q.eb1_t0});
}

template <class Query>
bool filter_culls(const Query& q, double thickness, int depth) {
  const Points p0 = ends(q, false), p1 = ends(q, true);
  for (const Points* p : {&p0, &p1}) {
    for (const Vec3& x : *p) {
      if (!x.allFinite()) throw std::invalid_argument("distance_filter_culls: non-finite input");
    }
  }
  const double m = move(q);
  const double eps = ccd_detail::coordinate_slack(
      {&p0[0], &p0[1], &p0[2], &p0[3], &p1[0], &p1[1], &p1[2], &p1[3]});
  // Lower bounds first: where they cull, the distances would too (the bound grows with them).
  if (culls(lower_bound(q, p0), lower_bound(q, p1), m, thickness, eps)) return true;
  return culls_on(0.0, 1.0, distance(q, p0), distance(q, p1), m, thickness, eps, depth,
                  [&](double t) {
                    Points pt;
                    for (int k = 0; k < 4; ++k)
                      pt[k] = at(p0[k], p1[k], t);
                    return distance(q, pt);
                  });
}

}  // namespace

bool distance_filter_culls(const VertexFaceQuery& q, double thickness, int depth) {
  return filter_culls(q, thickness, depth);
}

bool distance_filter_culls(const EdgeEdgeQuery& q, double thickness, int depth) {
  return filter_culls(q, thickness, depth);
}

bool distance_filter_culls(const TriangleTriangleQuery& q, double thickness) {
  for (const Vec3* x : {&q.a0_t0, &q.a1_t0, &q.a2_t0, &q.b0_t0, &q.b1_t0, &q.b2_t0, &q.a0_t1,
                        &q.a1_t1, &q.a2_t1, &q.b0_t1, &q.b1_t1, &q.b2_t1}) {
    if (!x->allFinite()) throw std::invalid_argument("distance_filter_culls: non-finite input");
  }
  return ccd_detail::triangles_filter_culls(
      {&q.a0_t0, &q.a1_t0, &q.a2_t0}, {&q.a0_t1, &q.a1_t1, &q.a2_t1},
      {&q.b0_t0, &q.b1_t0, &q.b2_t0}, {&q.b0_t1, &q.b1_t1, &q.b2_t1}, thickness);
}

}  // namespace clothcd
