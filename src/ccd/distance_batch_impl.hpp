#pragma once
// Internal: the body of distance_filter_batch (np_batch.hpp) for one xsimd architecture, included
// by the np_batch_*.cpp sources after np_batch_impl.hpp (their target flags, -ffp-contract=off,
// their NP_BATCH_NAMESPACE). Each lane performs the floating-point operations of
// distance_filter_culls (distance_filter.cpp, with the distances of proximity.cpp) in their
// order, a select standing for each branch, so every verdict is the scalar one. It leaves out the
// scalar filter's first try with the distances' lower bounds: where that culls, the distances
// cull too (queries.hpp), so the verdict is the same without it. min_of and max_of (lanes.hpp)
// select as std::min and std::max do.

#include <xsimd/xsimd.hpp>

#include <cmath>
#include <limits>

#include "ccd/np_batch_impl.hpp"

namespace clothcd::ccd_detail {
namespace NP_BATCH_NAMESPACE {
namespace distance {

using simd::lanes::max_of;
using simd::lanes::min_of;

// p + s (q - p), coordinate by coordinate (Eigen's p + s * (q - p)).
template <class B>
Vec3<B> along(const Vec3<B>& p, const Vec3<B>& q, const B& s) {
  return {p.x + s * (q.x - p.x), p.y + s * (q.y - p.y), p.z + s * (q.z - p.z)};
}

// point_segment_parameter: std::clamp is std::min(std::max(v, 0), 1).
template <class B>
B segment_parameter(const Vec3<B>& p, const Vec3<B>& a, const Vec3<B>& b) {
  const Vec3<B> e = sub(b, a);
  const B len2 = dot(e, e);
  const B zero(0.0), one(1.0);
  const B s = min_of(max_of(dot(sub(p, a), e) / len2, zero), one);
  return xsimd::select(len2 > zero, s, zero);
}

// The distance of point_triangle_closest: the square root of the least squared distance of its
// candidates (comparing squares first gives the same distance, sqrt being monotonic).
template <class B>
B point_triangle_distance(const Vec3<B>& p, const Vec3<B>& f0, const Vec3<B>& f1,
                          const Vec3<B>& f2) {
  const Vec3<B>* v[3] = {&f0, &f1, &f2};
  B best2(std::numeric_limits<double>::infinity());
  for (int i = 0; i < 3; ++i) {
    const Vec3<B>& a = *v[i];
    const Vec3<B>& b = *v[(i + 1) % 3];
    const Vec3<B> d = sub(p, along(a, b, segment_parameter(p, a, b)));
    const B d2 = dot(d, d);
    best2 = xsimd::select(d2 < best2, d2, best2);
  }
  const Vec3<B> e1 = sub(f1, f0), e2 = sub(f2, f0), w = sub(p, f0);
  const B g11 = dot(e1, e1), g12 = dot(e1, e2), g22 = dot(e2, e2);
  const B r1 = dot(w, e1), r2 = dot(w, e2);
  const B det = g11 * g22 - g12 * g12;
  const B a = (r1 * g22 - r2 * g12) / det;
  const B b = (r2 * g11 - r1 * g12) / det;
  const B zero(0.0), one(1.0);
  const auto inside = (det > B(1e-12) * g11 * g22) && (a >= zero) && (b >= zero) && (a + b <= one);
  const Vec3<B> c = {f0.x + a * e1.x + b * e2.x, f0.y + a * e1.y + b * e2.y,
                     f0.z + a * e1.z + b * e2.z};
  const Vec3<B> d = sub(p, c);
  const B d2 = dot(d, d);
  return xsimd::sqrt(xsimd::select(inside && d2 < best2, d2, best2));
}

// The distance of edge_edge_closest, likewise.
template <class B>
B edge_edge_distance(const Vec3<B>& ea0, const Vec3<B>& ea1, const Vec3<B>& eb0,
                     const Vec3<B>& eb1) {
  B best2(std::numeric_limits<double>::infinity());
  const auto consider = [&](const B& s, const B& t, const auto& valid) {
    const Vec3<B> d = sub(along(ea0, ea1, s), along(eb0, eb1, t));
    const B d2 = dot(d, d);
    best2 = xsimd::select(valid && d2 < best2, d2, best2);
  };
  const B zero(0.0), one(1.0);
  const auto all = zero == zero;
  consider(zero, segment_parameter(ea0, eb0, eb1), all);
  consider(one, segment_parameter(ea1, eb0, eb1), all);
  consider(segment_parameter(eb0, ea0, ea1), zero, all);
  consider(segment_parameter(eb1, ea0, ea1), one, all);
  const Vec3<B> da = sub(ea1, ea0), db = sub(eb1, eb0), r = sub(ea0, eb0);
  const B a = dot(da, da), b = dot(da, db), c = dot(db, db), d = dot(da, r), e = dot(db, r);
  const B den = a * c - b * b;
  const B s = min_of(max_of((b * e - c * d) / den, zero), one);
  const B t = min_of(max_of((a * e - b * d) / den, zero), one);
  consider(s, t, den > B(1e-14) * a * c);
  return xsimd::sqrt(best2);
}

// coordinate_slack (slack.hpp) of N points.
template <class B, int N>
B slack(const Vec3<B>* const (&p)[N]) {
  B m(1.0);
  for (const Vec3<B>* x : p)
    m = max_of(m, max_of(max_of(xsimd::abs(x->x), xsimd::abs(x->y)), xsimd::abs(x->z)));
  return B(1e-12) * m;
}

template <class B>
B feature_distance(Kind kind, const Vec3<B> (&p)[4]) {
  return kind == Kind::VertexFace ? point_triangle_distance(p[0], p[1], p[2], p[3])
                                  : edge_edge_distance(p[0], p[1], p[2], p[3]);
}

// largest_relative_move: the largest distance a moving point of the first feature (a vertex, or
// an edge's two ends) travels relative to one of the second.
template <class B>
B largest_move(Kind kind, const Vec3<B> (&x0)[4], const Vec3<B> (&x1)[4]) {
  Vec3<B> m[4];
  for (int k = 0; k < 4; ++k)
    m[k] = sub(x1[k], x0[k]);
  const int first = kind == Kind::VertexFace ? 1 : 2;
  B d(0.0);
  for (int i = 0; i < first; ++i) {
    for (int j = first; j < 4; ++j) {
      const Vec3<B> r = sub(m[i], m[j]);
      d = max_of(d, dot(r, r));
    }
  }
  return xsimd::sqrt(d);
}

// culls of distance_filter.cpp.
template <class B>
auto culls(const B& d0, const B& d1, const B& move, const B& limit) {
  const B bound = B(0.5) * (d0 + d1 - move);
  return xsimd::isfinite(bound) && bound > limit;
}

// culls_on of distance_filter.cpp over [ta, tb] for every lane: a lane's verdict does not depend
// on the others', so computing a midpoint distance some lanes do not need changes nothing. The
// second half is bounded only where the first culls (the scalar code's &&).
template <class B, class Dist>
auto culls_on(double ta, double tb, const B& da, const B& db, const B& move, const B& limit,
              int depth, const Dist& dist) {
  const auto whole = culls(da, db, move * B(tb - ta), limit);
  if (depth <= 0) return whole;
  const auto deeper = !whole && min_of(da, db) > limit;
  if (!xsimd::any(deeper)) return whole;
  const double tm = 0.5 * (ta + tb);
  const B dm = dist(tm);
  const auto first = deeper && culls_on(ta, tm, da, dm, move, limit, depth - 1, dist);
  if (!xsimd::any(first)) return whole;
  return whole || (first && culls_on(tm, tb, dm, db, move, limit, depth - 1, dist));
}

}  // namespace distance

// distance_filter_batch (np_batch.hpp): the kept queries W at a time (a partial group repeats its
// last query).
template <class Arch>
void distance_filter_batch_impl(Kind kind, const NpBatch& b, double thickness, int depth,
                                NpVerdict* verdict) {
  using B = xsimd::batch<double, Arch>;
  using V = Vec3<B>;
  constexpr int W = static_cast<int>(B::size);
  int kept[NpBatch::kCapacity];
  int nk = 0;
  for (int i = 0; i < b.size; ++i) {
    kept[nk] = i;
    nk += verdict[i] == NpVerdict::Kept ? 1 : 0;
  }
  for (int s = 0; s < nk; s += W) {
    const int n = nk - s < W ? nk - s : W;
    alignas(64) double col[24][W];
    gather_kept(b, kept + s, n, col);
    V x0[4], x1[4];
    for (int p = 0; p < 4; ++p) {
      x0[p] = V{B::load_aligned(col[3 * p]), B::load_aligned(col[3 * p + 1]),
                B::load_aligned(col[3 * p + 2])};
      x1[p] = V{B::load_aligned(col[3 * p + 12]), B::load_aligned(col[3 * p + 13]),
                B::load_aligned(col[3 * p + 14])};
    }
    const V* const all[8] = {&x0[0], &x0[1], &x0[2], &x0[3], &x1[0], &x1[1], &x1[2], &x1[3]};
    const B eps = distance::slack(all);
    const B move = distance::largest_move(kind, x0, x1);
    const B limit = B(thickness) + eps;
    const auto at = [&](double t) {
      V p[4];
      for (int k = 0; k < 4; ++k)
        p[k] = distance::along(x0[k], x1[k], B(t));
      return distance::feature_distance(kind, p);
    };
    const auto cull =
        distance::culls_on(0.0, 1.0, distance::feature_distance(kind, x0),
                           distance::feature_distance(kind, x1), move, limit, depth, at);
    const unsigned bits = lane_bits(cull);
    for (int l = 0; l < n; ++l) {
      if (((bits >> l) & 1u) != 0) verdict[kept[s + l]] = NpVerdict::Culled;
    }
  }
}

}  // namespace NP_BATCH_NAMESPACE
}  // namespace clothcd::ccd_detail
