// Bergou et al. 2006 quadratic bending against a flat rest state (docs/simulator.md 1.3).
#include <algorithm>
#include <cmath>

#include "clothcd/sim/elements.hpp"

namespace clothcd::sim {

double cotangent(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u = b - a;
  const Vec3 v = c - a;
  const double sin_area = u.cross(v).norm();
  const double cos_term = u.dot(v);
  if (sin_area == 0.0) return cos_term >= 0.0 ? INFINITY : -INFINITY;
  return cos_term / sin_area;
}

HingeWeights bending_weights(const std::array<Vec3, 4>& rest, double k_bending, double cot_clamp) {
  auto clamp = [cot_clamp](double c) { return std::clamp(c, -cot_clamp, cot_clamp); };
  const Vec3& x0 = rest[0];
  const Vec3& x1 = rest[1];
  const Vec3& x2 = rest[2];
  const Vec3& x3 = rest[3];
  const double c01 = clamp(cotangent(x0, x1, x2));  // triangle 0 at x0
  const double c03 = clamp(cotangent(x1, x0, x2));  // triangle 0 at x1
  const double c02 = clamp(cotangent(x0, x1, x3));  // triangle 1 at x0
  const double c04 = clamp(cotangent(x1, x0, x3));  // triangle 1 at x1
  const double a0 = 0.5 * (x1 - x0).cross(x2 - x0).norm();
  const double a1 = 0.5 * (x1 - x0).cross(x3 - x0).norm();
  HingeWeights w;
  w.k = {c03 + c04, c01 + c02, -c01 - c03, -c02 - c04};
  w.scale = a0 + a1 > 0.0 ? 6.0 * k_bending / (a0 + a1) : 0.0;
  return w;
}

double bending_energy(const HingeWeights& w, const std::array<Vec3, 4>& x) {
  Vec3 s = Vec3::Zero();
  for (int m = 0; m < 4; ++m)
    s += w.k[m] * x[m];
  return 0.5 * w.scale * s.squaredNorm();
}

}  // namespace clothcd::sim
