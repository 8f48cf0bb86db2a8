#include "sphere_caps.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "clothcd/geometry/angle.hpp"

namespace clothcd::detail {

namespace {

// Below this squared length a tangent is treated as undefined: its square would underflow.
constexpr double kTinySquared = 1e-280;

// The stereographic image of unit direction `q` in the tangent plane at unit `p` (p maps to 0):
// radius 2 tan(beta / 2) along the tangent toward q. False when q is antipodal to p.
// tan(beta / 2) = |p - q| / |p + q| for unit vectors: both lengths are exact differences or sums
// of nearly equal numbers where it matters, and the last-bit radial error of p and q moves them
// only to second order. The form sin / (1 + cos) would cancel catastrophically near q = -p.
bool stereographic(const Eigen::Vector3d& p, const Eigen::Vector3d& q, Eigen::Vector3d& image) {
  const double plus = (p + q).norm();
  if (!(plus > 1e-300)) return false;
  const Eigen::Vector3d w = tangent_toward(p, q);
  image = (2.0 * (p - q).norm() / plus) * w;  // w = 0 when q is parallel to p: image 0
  return image.allFinite();
}

}  // namespace

Eigen::Vector3d tangent_toward(const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d v = precise_cross(p, q).cross(p);
  const double n2 = v.squaredNorm();
  if (!(n2 > kTinySquared)) return Eigen::Vector3d::Zero();
  return v / std::sqrt(n2);
}

Eigen::Vector3d rotate_toward(const Eigen::Vector3d& p, const Eigen::Vector3d& w, double alpha) {
  return (std::cos(alpha) * p + std::sin(alpha) * w).normalized();
}

NormalCone diametral_cap(const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const double beta = angle_between(p, q);
  const Eigen::Vector3d w = tangent_toward(p, q);
  if (w.isZero()) {
    // Parallel within ~1e-140 rad (any axis between them works) or antiparallel (saturated).
    if (p.dot(q) > 0.0) return {p.normalized(), beta};
    return saturated_cone(p.normalized());
  }
  const double half = 0.5 * beta;
  if (!(half < kSaturatedHalfAngle)) return saturated_cone(p.normalized());
  return {rotate_toward(p.normalized(), w, half), half};
}

NormalCone circumcap(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
  const Eigen::Vector3d pn = p.normalized(), qn = q.normalized(), rn = r.normalized();
  // Project stereographically from the antipode of c, a point near the cap centre: the images
  // then have moderate size whatever the cap (projecting from one of the three points would
  // send points near its antipode far away and lose precision near pi/2).
  const Eigen::Vector3d sum = pn + qn + rn;
  if (!(sum.squaredNorm() > 1e-200)) return saturated_cone(pn);
  const Eigen::Vector3d c = sum.normalized();
  Eigen::Vector3d a, b, d;
  if (!stereographic(c, pn, a) || !stereographic(c, qn, b) || !stereographic(c, rn, d)) {
    return saturated_cone(pn);
  }
  // Planar circumcircle (centre m, radius rho) of the images, relative to a.
  const Eigen::Vector3d ab = b - a, ad = d - a;
  const Eigen::Vector3d n = ab.cross(ad);
  const double n2 = n.squaredNorm();
  if (!(n2 > 1e-24 * ab.squaredNorm() * ad.squaredNorm()) || !(n2 > kTinySquared)) {
    return saturated_cone(pn);  // collinear images: the three lie on a great circle (or repeat)
  }
  const Eigen::Vector3d rel = (ab.squaredNorm() * ad - ad.squaredNorm() * ab).cross(n) / (2.0 * n2);
  const Eigen::Vector3d m = a + rel;
  const double rho = rel.norm();
  const double mlen = m.norm();
  if (!std::isfinite(mlen) || !std::isfinite(rho)) return saturated_cone(pn);
  // The circle crosses the ray from 0 through m at signed radii mlen -+ rho, i.e. at angles
  // 2 atan(x / 2) from c along that great circle; the cap centre lies halfway between.
  const double phi_near = 2.0 * std::atan(0.5 * (mlen - rho));
  const double phi_far = 2.0 * std::atan(0.5 * (mlen + rho));
  const double theta = 0.5 * (phi_far - phi_near);
  if (!(theta < kSaturatedHalfAngle)) return saturated_cone(pn);
  if (mlen == 0.0) return {c, theta};
  return {rotate_toward(c, m / mlen, 0.5 * (phi_far + phi_near)), theta};
}

double max_angle_from(const Eigen::Vector3d& axis, const Eigen::Vector3d* dirs, std::size_t count) {
  double max_tan = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const double d = axis.dot(dirs[i]);
    if (!(d > 0.0)) return kSaturatedHalfAngle;
    max_tan = std::max(max_tan, precise_cross(axis, dirs[i]).norm() / d);
  }
  return std::atan(max_tan);
}

NormalCone minimal_cap(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                       const Eigen::Vector3d* r) {
  const Eigen::Vector3d dirs[3] = {p, q, r != nullptr ? *r : p};
  const std::size_t count = r != nullptr ? 3 : 2;
  NormalCone best = saturated_cone(p.normalized());
  auto consider = [&](const NormalCone& candidate) {
    if (candidate.saturated()) return;
    const double theta = max_angle_from(candidate.axis, dirs, count);
    if (theta < best.half_angle) best = {candidate.axis, theta};
  };
  consider(diametral_cap(p, q));
  if (r != nullptr) {
    consider(diametral_cap(p, *r));
    consider(diametral_cap(q, *r));
    consider(circumcap(p, q, *r));
  }
  return best;
}

}  // namespace clothcd::detail
