#include "ccd/certify.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>

namespace clothcd::ccd_detail {

namespace {

constexpr double kUnitRoundoff = DBL_EPSILON / 2;

// Midpoint-radius interval: the value lies in [m - r, m + r] (up to the slack of the final bound).
struct I {
  double m, r;
};
inline I mul(I a, I b) {
  return {a.m * b.m, std::abs(a.m) * b.r + std::abs(b.m) * a.r + a.r * b.r};
}
inline I sub(I a, I b) {
  return {a.m - b.m, a.r + b.r};
}
inline I add(I a, I b) {
  return {a.m + b.m, a.r + b.r};
}

struct IV {
  I x, y, z;
};
inline IV cross(const IV& a, const IV& b) {
  return {sub(mul(a.y, b.z), mul(a.z, b.y)), sub(mul(a.z, b.x), mul(a.x, b.z)),
          sub(mul(a.x, b.y), mul(a.y, b.x))};
}
inline I dot(const IV& a, const IV& b) {
  return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z));
}

inline void diff(const Eigen::Vector3d& p, const Eigen::Vector3d& q, double (&out)[3]) {
  for (int c = 0; c < 3; ++c)
    out[c] = p[c] - q[c];
}

}  // namespace

InsideData inside_data(Kind kind, const Motion& m) {
  InsideData d;
  d.kind = kind;
  // Pairs (p, q) of point indices: vector k = x[p] - x[q] (motion order VF: v f0 f1 f2,
  // EE: a0 a1 b0 b1).
  static constexpr int kVf[5][2] = {{2, 1}, {3, 1}, {0, 1}, {3, 2}, {0, 2}};  // e1 e2 r e3 s
  static constexpr int kEe[5][2] = {{1, 0}, {3, 2}, {2, 0}, {1, 2}, {0, 3}};  // ea eb d w z
  const auto& idx = kind == Kind::VertexFace ? kVf : kEe;
  double a = 0;
  for (int k = 0; k < 5; ++k) {
    diff(m.x0[idx[k][0]], m.x0[idx[k][1]], d.x0[k]);
    diff(m.x1[idx[k][0]], m.x1[idx[k][1]], d.x1[k]);
    for (int c = 0; c < 3; ++c)
      a = std::max({a, std::abs(d.x0[k][c]), std::abs(d.x1[k][c])});
  }
  d.a_max = a;
  return d;
}

Inside inside_over(const InsideData& d, double lo, double hi, double& u, double& v) {
  // Forward error bound (docs/ccd.md): with every level-1 interval within M = a_max (1 + 1e-12)
  // of 0, the computed interval misses the exact range by at most ~870 u M^4 (interpolation
  // 9 u M, cross products 64 u M^2, dot products of magnitude <= 12 M^4); 2048 leaves margin for
  // the final subtraction. The absolute term covers underflow (M <= 2 after rescaling).
  const double mm = d.a_max * (1 + 1e-12);
  const double e = 2048 * kUnitRoundoff * (mm * mm) * (mm * mm) +
                   16384 * std::numeric_limits<double>::denorm_min();
  // Each difference moves linearly in t, so over [lo, hi] it lies between its values at the two
  // ends: midpoint-radius of those.
  const auto at = [&](int k) {
    I c[3];
    for (int a = 0; a < 3; ++a) {
      const double dx = d.x1[k][a] - d.x0[k][a];
      const double p = d.x0[k][a] + lo * dx, q = d.x0[k][a] + hi * dx;
      c[a] = I{(p + q) * 0.5, std::abs(q - p) * 0.5};
    }
    return IV{c[0], c[1], c[2]};
  };
  // The answer is No as soon as one function is below -e over the range, whichever it is, so each
  // is tested as soon as it is computed; the others (and u, v) are needed only otherwise.
  const auto below = [&](const I& g) { return g.m + g.r < -e; };
  const auto above = [&](const I& g) { return g.m - g.r > e; };
  const IV x0 = at(0), x1 = at(1), x2 = at(2);
  const IV n = cross(x0, x1);
  if (d.kind == Kind::VertexFace) {
    const I gc = dot(n, cross(x0, x2));  // weight of c
    if (below(gc)) return Inside::No;
    const IV x3 = at(3), x4 = at(4);
    const I ga = dot(n, cross(x3, x4));  // weight of a
    if (below(ga)) return Inside::No;
    const I gb = dot(n, cross(x2, x1));  // weight of b
    if (below(gb)) return Inside::No;
    const double sum = gc.m + ga.m + gb.m;
    u = sum != 0 ? gb.m / sum : 0;
    v = sum != 0 ? gc.m / sum : 0;
    return above(gc) && above(ga) && above(gb) ? Inside::Yes : Inside::Unknown;
  }
  const I gu = dot(n, cross(x2, x1));  // u |n|^2
  if (below(gu)) return Inside::No;
  const IV x3 = at(3);
  const I gu1 = dot(n, cross(x3, x1));  // (1 - u) |n|^2
  if (below(gu1)) return Inside::No;
  const I gv = dot(n, cross(x2, x0));  // v |n|^2
  if (below(gv)) return Inside::No;
  const IV x4 = at(4);
  const I gv1 = dot(n, cross(x4, x0));  // (1 - v) |n|^2
  if (below(gv1)) return Inside::No;
  const double su = gu.m + gu1.m, sv = gv.m + gv1.m;
  u = su != 0 ? gu.m / su : 0;
  v = sv != 0 ? gv.m / sv : 0;
  return above(gu) && above(gu1) && above(gv) && above(gv1) ? Inside::Yes : Inside::Unknown;
}

}  // namespace clothcd::ccd_detail
