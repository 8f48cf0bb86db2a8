#include "ccd/cubic.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>

namespace clothcd::ccd_detail {

namespace {

constexpr double kUnitRoundoff = DBL_EPSILON / 2;

struct V3 {
  double x, y, z;
};
inline V3 sub(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return {a.x() - b.x(), a.y() - b.y(), a.z() - b.z()};
}
inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double dot(const V3& a, const V3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline double max_abs(const V3& a) {
  return std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z)});
}

}  // namespace

namespace {

// x0[k], x1[k]: the four points at t = 0 and t = 1 in motion order. Also returns A, the largest
// |component| of the computed differences.
BernsteinCubic cubic_of(Kind kind, const Eigen::Vector3d* const* x0,
                        const Eigen::Vector3d* const* x1, double& a) {
  // Point indices of a, b, c, q in the motion's order.
  const int ia = kind == Kind::VertexFace ? 1 : 0;
  const int ib = kind == Kind::VertexFace ? 2 : 1;
  const int ic = kind == Kind::VertexFace ? 3 : 2;
  const int iq = kind == Kind::VertexFace ? 0 : 3;
  const V3 e1_0 = sub(*x0[ib], *x0[ia]), e2_0 = sub(*x0[ic], *x0[ia]);
  const V3 r0 = sub(*x0[iq], *x0[ia]);
  const V3 e1_1 = sub(*x1[ib], *x1[ia]), e2_1 = sub(*x1[ic], *x1[ia]);
  const V3 r1 = sub(*x1[iq], *x1[ia]);
  const V3 n0 = cross(e1_0, e2_0), n1 = cross(e1_1, e2_1);
  const V3 c01 = cross(e1_0, e2_1), c10 = cross(e1_1, e2_0);
  // 2 nX = e1_0 x e2_1 + e1_1 x e2_0 (the better-conditioned form of the middle control vector).
  const V3 nx2 = {c01.x + c10.x, c01.y + c10.y, c01.z + c10.z};
  BernsteinCubic c;
  c.k[0] = dot(n0, r0);
  c.k[1] = (dot(nx2, r0) + dot(n0, r1)) / 3;
  c.k[2] = (dot(nx2, r1) + dot(n1, r0)) / 3;
  c.k[3] = dot(n1, r1);
  // Forward error: with every computed difference at most A in magnitude, each coefficient is a
  // sum of monomials of degree 3 whose absolute values add up to at most 6 A^3 (times 3 for the
  // middle ones before the division), reached through at most ~12 roundings plus the relative
  // error u of each difference factor: below 100 u A^3. 256 leaves margin for rounding A^3
  // itself; the absolute term covers underflow (inputs are scaled so that |x| < 1).
  a = std::max(
      {max_abs(e1_0), max_abs(e2_0), max_abs(r0), max_abs(e1_1), max_abs(e2_1), max_abs(r1)});
  c.eta = 256 * kUnitRoundoff * (a * a * a) + 1024 * std::numeric_limits<double>::denorm_min();
  return c;
}

}  // namespace

BernsteinCubic coplanarity_cubic(Kind kind, const Motion& m) {
  const Eigen::Vector3d* x0[4] = {&m.x0[0], &m.x0[1], &m.x0[2], &m.x0[3]};
  const Eigen::Vector3d* x1[4] = {&m.x1[0], &m.x1[1], &m.x1[2], &m.x1[3]};
  double a = 0;
  return cubic_of(kind, x0, x1, a);
}

NpVerdict unscaled_np_filter(Kind kind, const std::array<const Eigen::Vector3d*, 8>& points) {
  for (const Eigen::Vector3d* p : points) {
    if (!p->allFinite()) return NpVerdict::Undecided;
  }
  double a = 0;
  const BernsteinCubic c = cubic_of(kind, points.data(), points.data() + 4, a);
  // Without the rescaling the same bound holds while nothing overflows (A <= 2^100: every
  // intermediate stays below ~2^305) and underflow stays negligible: each underflowing rounding
  // adds at most denorm_min / 2, grown by at most two later factors <= 2^101, so below 2^-968 in
  // all, while the bound's slack (256 - 100) u A^3 is at least 2^-946 for A >= 2^-300.
  constexpr double kLow = 0x1p-300, kHigh = 0x1p100;
  if (!(a >= kLow && a <= kHigh)) return NpVerdict::Undecided;
  return np_culls(c) ? NpVerdict::Culled : NpVerdict::Kept;
}

bool np_culls(const BernsteinCubic& c) {
  const double e = c.eta;
  return (c.k[0] > e && c.k[1] > e && c.k[2] > e && c.k[3] > e) ||
         (c.k[0] < -e && c.k[1] < -e && c.k[2] < -e && c.k[3] < -e);
}

double subdivision_error(const BernsteinCubic& c) {
  // De Casteljau halving forms averages: each value stays within the convex hull of the
  // coefficients (|.| <= K), each level adds at most one rounding of u K to three of them, and
  // errors already present do not grow. 40 levels of 3 averages: 120 u K < 128 u K.
  const double kmax =
      std::max({std::abs(c.k[0]), std::abs(c.k[1]), std::abs(c.k[2]), std::abs(c.k[3])});
  return c.eta + 128 * kUnitRoundoff * kmax;
}

}  // namespace clothcd::ccd_detail
