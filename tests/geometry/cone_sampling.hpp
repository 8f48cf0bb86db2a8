#pragma once
// Seeded sampling and long-double oracles shared by the cone tests. Every random draw goes
// through Rng, so a failing case reproduces from the seed printed with it.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

#include "clothcd/geometry/cone.hpp"

namespace clothcd::test {

#ifdef CLOTHCD_TEST_SANITIZED
inline constexpr int kCases = 10'000;
#else
inline constexpr int kCases = 100'000;
#endif

using Vec3L = Eigen::Matrix<long double, 3, 1>;

inline Vec3L to_ld(const Eigen::Vector3d& v) {
  return v.cast<long double>();
}

/// The angle between two vectors in long double (atan2 form): the oracle for containment.
inline long double angle_ld(const Vec3L& u, const Vec3L& v) {
  return std::atan2(u.cross(v).norm(), u.dot(v));
}
inline long double angle_ld(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  return angle_ld(to_ld(u), to_ld(v));
}

/// Portable seeded generator (mt19937_64 bits, our own conversion to doubles).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : gen_(seed) {}
  double uniform() { return static_cast<double>(gen_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  bool chance(double p) { return uniform() < p; }
  int integer(int lo, int hi) { return lo + static_cast<int>(gen_() % (hi - lo + 1)); }
  Eigen::Vector3d unit() {
    const double z = uniform(-1.0, 1.0);
    const double phi = uniform(0.0, 2.0 * std::numbers::pi);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }
  /// A unit vector perpendicular to unit `a`.
  Eigen::Vector3d perpendicular(const Eigen::Vector3d& a) {
    for (;;) {
      const Eigen::Vector3d v = a.cross(unit());
      if (v.norm() > 0.1) return v.normalized();
    }
  }
  std::uint64_t bits() { return gen_(); }

 private:
  std::mt19937_64 gen_;
};

/// The direction at `angle` from unit `a` toward unit `dir` (perpendicular to a), rounded once.
inline Eigen::Vector3d rotate(const Eigen::Vector3d& a, const Eigen::Vector3d& dir,
                              long double angle) {
  const Vec3L v = std::cos(angle) * to_ld(a) + std::sin(angle) * to_ld(dir);
  return v.normalized().cast<double>();
}

/// A point on the rim of a (non-saturated) cone, at azimuth `phi`.
inline Eigen::Vector3d rim_point(const NormalCone& c, double phi) {
  const Vec3L a = to_ld(c.axis).normalized();
  const Vec3L u = a.unitOrthogonal();
  const Vec3L v = a.cross(u);
  const long double t = c.half_angle;
  const Vec3L p = std::cos(t) * a + std::sin(t) * (std::cos(phi) * u + std::sin(phi) * v);
  return p.cast<double>();
}

/// A random cone with half-angle `theta` around a random axis.
inline NormalCone random_cone(Rng& rng, double theta) {
  return {rng.unit(), theta};
}

/// A random pair of cones at one angular scale drawn log-uniformly from [1e-9, pi/2], covering
/// disjoint, overlapping, inclusive, identical-axis and wide (saturating) configurations.
struct ConePair {
  NormalCone a, b;
  double scale;
};
inline ConePair random_cone_pair(Rng& rng) {
  const double s = rng.log_uniform(1e-9, std::numbers::pi / 2);
  auto angle = [&] {
    const double r = rng.uniform();
    if (r < 0.08) return 0.0;
    return s * rng.uniform(0.0, 1.0);
  };
  const double t1 = angle(), t2 = angle();
  double beta = 0.0;
  const double mode = rng.uniform();
  if (mode < 0.05) {
    beta = 0.0;  // identical axes
  } else if (mode < 0.25) {
    beta = std::abs(t1 - t2) * rng.uniform();  // inclusive
  } else if (mode < 0.9) {
    beta = s * rng.uniform(0.0, 2.0);
  } else {
    beta = rng.uniform(0.0, std::numbers::pi);  // anything, often saturating
  }
  const Eigen::Vector3d a1 = rng.unit();
  const Eigen::Vector3d a2 = rotate(a1, rng.perpendicular(a1), beta);
  if (rng.chance(0.5)) return {{a1, t1}, {a2, t2}, s};
  return {{a2, t2}, {a1, t1}, s};
}

}  // namespace clothcd::test
