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
  // Each difference moves linearly in t, so over [lo, hi] it lies between its values at the two
  // ends: midpoint-radius of those.
  IV x[5];
  for (int k = 0; k < 5; ++k) {
    I* comp[3] = {&x[k].x, &x[k].y, &x[k].z};
    for (int c = 0; c < 3; ++c) {
      const double dx = d.x1[k][c] - d.x0[k][c];
      const double a = d.x0[k][c] + lo * dx, b = d.x0[k][c] + hi * dx;
      *comp[c] = I{(a + b) * 0.5, std::abs(b - a) * 0.5};
    }
  }
  I g[4];
  int count;
  if (d.kind == Kind::VertexFace) {
    const IV n = cross(x[0], x[1]);
    g[0] = dot(n, cross(x[0], x[2]));  // weight of c
    g[1] = dot(n, cross(x[3], x[4]));  // weight of a
    g[2] = dot(n, cross(x[2], x[1]));  // weight of b
    count = 3;
    const double sum = g[0].m + g[1].m + g[2].m;
    u = sum != 0 ? g[2].m / sum : 0;
    v = sum != 0 ? g[0].m / sum : 0;
  } else {
    const IV n = cross(x[0], x[1]);
    g[0] = dot(n, cross(x[2], x[1]));  // u |n|^2
    g[1] = dot(n, cross(x[3], x[1]));  // (1 - u) |n|^2
    g[2] = dot(n, cross(x[2], x[0]));  // v |n|^2
    g[3] = dot(n, cross(x[4], x[0]));  // (1 - v) |n|^2
    count = 4;
    const double su = g[0].m + g[1].m, sv = g[2].m + g[3].m;
    u = su != 0 ? g[0].m / su : 0;
    v = sv != 0 ? g[2].m / sv : 0;
  }
  // Forward error bound (docs/ccd.md): with every level-1 interval within M = a_max (1 + 1e-12)
  // of 0, the computed interval misses the exact range by at most ~870 u M^4 (interpolation
  // 9 u M, cross products 64 u M^2, dot products of magnitude <= 12 M^4); 2048 leaves margin for
  // the final subtraction. The absolute term covers underflow (M <= 2 after rescaling).
  const double mm = d.a_max * (1 + 1e-12);
  const double e = 2048 * kUnitRoundoff * (mm * mm) * (mm * mm) +
                   16384 * std::numeric_limits<double>::denorm_min();
  bool all_positive = true;
  for (int i = 0; i < count; ++i) {
    if (g[i].m + g[i].r < -e) return Inside::No;
    all_positive = all_positive && g[i].m - g[i].r > e;
  }
  return all_positive ? Inside::Yes : Inside::Unknown;
}

}  // namespace clothcd::ccd_detail
