#include "ccd/inclusion.hpp"

#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <limits>

namespace clothcd::ccd_detail {

namespace {

constexpr double kUnitRoundoff = DBL_EPSILON / 2;
// Total splits along one path. Each split halves one parameter's contribution to the width of F,
// so a box reaches any tolerance above the rounding noise long before this; it only guards
// against pathological inputs (a box this deep is reported as a hit).
constexpr int kMaxDepth = 200;
// Depth-first: each split pops one box and pushes two, so the stack never exceeds kMaxDepth + 1.
constexpr int kStackSize = kMaxDepth + 8;

struct Box {
  double t0, t1, u0, u1, v0, v1;
  int depth;
};

// Corner values of F: [time][u][v][axis].
using Corners = double[2][2][2][3];

template <Kind K>
inline void eval_corners(const Motion& m, const double (&d)[4][3], const Box& b, Corners& f) {
  for (int it = 0; it < 2; ++it) {
    const double t = it == 0 ? b.t0 : b.t1;
    for (int a = 0; a < 3; ++a) {
      // Positions at time t, computed as x0 + t * (x1 - x0) (the order the error bound assumes).
      const double p0 = m.x0[0][a] + t * d[0][a];
      const double p1 = m.x0[1][a] + t * d[1][a];
      const double p2 = m.x0[2][a] + t * d[2][a];
      const double p3 = m.x0[3][a] + t * d[3][a];
      if constexpr (K == Kind::VertexFace) {
        const double w = p0 - p1, e1 = p2 - p1, e2 = p3 - p1;
        for (int iu = 0; iu < 2; ++iu) {
          const double wu = w - (iu == 0 ? b.u0 : b.u1) * e1;
          f[it][iu][0][a] = wu - b.v0 * e2;
          f[it][iu][1][a] = wu - b.v1 * e2;
        }
      } else {
        const double ea = p1 - p0, eb = p3 - p2;
        const double a0 = p0 + b.u0 * ea, a1 = p0 + b.u1 * ea;
        const double c0 = p2 + b.v0 * eb, c1 = p2 + b.v1 * eb;
        f[it][0][0][a] = a0 - c0;
        f[it][0][1][a] = a0 - c1;
        f[it][1][0][a] = a1 - c0;
        f[it][1][1][a] = a1 - c1;
      }
    }
  }
}

template <Kind K>
InclusionOutcome solve(const Motion& m, const InclusionParams& p) {
  double d[4][3];
  for (int k = 0; k < 4; ++k) {
    for (int a = 0; a < 3; ++a)
      d[k][a] = m.x1[k][a] - m.x0[k][a];
  }
  double thr[3];
  double max_err = 0;
  for (int a = 0; a < 3; ++a) {
    const double err = corner_error_bound(m.max_abs[a]);
    max_err = std::max(max_err, err);
    // Round the threshold up so that the comparison itself cannot reject a contact.
    thr[a] = std::nextafter(p.thickness + err, INFINITY);
  }
  // A tolerance below the rounding noise could never be met.
  const double tol = std::max(p.tolerance, 16 * max_err);

  InclusionOutcome out;
  Box stack[kStackSize];
  int n = 0;
  stack[n++] = Box{p.t_lo, p.t_hi, 0, 1, 0, 1, 0};
  double toi = INFINITY;
  // Boxes skipped because they could lower the time of impact by less than p.toi_tolerance: the
  // earliest of their start times still bounds the reported time of impact from below.
  double skipped_t0 = INFINITY;
  Corners f;
  while (n > 0) {
    const Box b = stack[--n];
    // Only an earlier box can lower the time of impact already found, and only one starting
    // more than toi_tolerance earlier is worth refining.
    if (b.t0 >= toi) continue;
    if (b.t0 >= toi - p.toi_tolerance) {
      skipped_t0 = std::min(skipped_t0, b.t0);
      continue;
    }
    // Exact: box bounds are dyadic with few bits.
    if (K == Kind::VertexFace && b.u0 + b.v0 > 1) continue;
    if (++out.boxes > p.max_boxes) {
      // Out of budget: every contact lies in a box still open, so the earliest open time is a
      // conservative time of impact.
      double t = std::min({toi, skipped_t0, b.t0});
      for (int i = 0; i < n; ++i)
        t = std::min(t, stack[i].t0);
      out.hit = true;
      out.toi = t;
      out.u = (b.u0 + b.u1) / 2;
      out.v = (b.v0 + b.v1) / 2;
      return out;
    }
    eval_corners<K>(m, d, b, f);
    bool rejected = false;
    double width = 0;
    for (int a = 0; a < 3 && !rejected; ++a) {
      double lo = f[0][0][0][a], hi = lo;
      for (int i = 1; i < 8; ++i) {
        const double x = (&f[0][0][0][0])[i * 3 + a];
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
      rejected = lo > thr[a] || hi < -thr[a];
      width = std::max(width, hi - lo);
    }
    if (rejected) continue;
    if (width <= tol || b.depth >= kMaxDepth) {
      toi = b.t0;
      out.hit = true;
      out.u = (b.u0 + b.u1) / 2;
      out.v = (b.v0 + b.v1) / 2;
      continue;
    }
    // Split the parameter that contributes most to the width of F: F is affine in each
    // parameter, so halving it halves that contribution.
    double wt = 0, wu = 0, wv = 0;
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        for (int a = 0; a < 3; ++a) {
          wt = std::max(wt, std::abs(f[1][i][j][a] - f[0][i][j][a]));
          wu = std::max(wu, std::abs(f[i][1][j][a] - f[i][0][j][a]));
          wv = std::max(wv, std::abs(f[i][j][1][a] - f[i][j][0][a]));
        }
      }
    }
    assert(n + 2 <= kStackSize);
    Box lo = b, hi = b;
    lo.depth = hi.depth = b.depth + 1;
    if (wt >= wu && wt >= wv) {
      const double mid = (b.t0 + b.t1) / 2;
      lo.t1 = hi.t0 = mid;
    } else if (wu >= wv) {
      const double mid = (b.u0 + b.u1) / 2;
      lo.u1 = hi.u0 = mid;
    } else {
      const double mid = (b.v0 + b.v1) / 2;
      lo.v1 = hi.v0 = mid;
    }
    // Earlier half on top, so the first hit found is early and prunes the rest.
    stack[n++] = hi;
    stack[n++] = lo;
  }
  if (out.hit) out.toi = std::min(toi, skipped_t0);
  return out;
}

}  // namespace

double corner_error_bound(double max_abs) {
  // 51 u max_abs derived in docs/ccd.md; 64 leaves room for rounding the bound itself. The
  // absolute term covers underflow in the (at most 12) operations behind one corner value.
  return 64 * kUnitRoundoff * max_abs + 64 * std::numeric_limits<double>::denorm_min();
}

InclusionOutcome inclusion_solve(Kind kind, const Motion& m, const InclusionParams& p) {
  return kind == Kind::VertexFace ? solve<Kind::VertexFace>(m, p) : solve<Kind::EdgeEdge>(m, p);
}

}  // namespace clothcd::ccd_detail
