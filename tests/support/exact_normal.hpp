#pragma once
// The exact normal of a linearly moving triangle, in rational arithmetic (GMP): doubles convert
// to rationals exactly, so the direction returned is the true one for the given coordinates,
// rounded once at the end. Checks of normal cones compare against it with no error model of their
// own (an error model that misjudged the rounding of interpolated positions once made a correct
// leaf cone look wrong).

#include <gmpxx.h>

#include <Eigen/Core>
#include <array>
#include <optional>

namespace clothcd::test {

/// The unit normal direction of triangle (a, b, c) at t = num / den of the motion from the t0
/// to the t1 positions, or nothing where the triangle is exactly degenerate at that time.
/// Accurate to a few units in the last place of each component.
inline std::optional<Eigen::Vector3d> exact_normal(const std::array<Eigen::Vector3d, 3>& t0,
                                                   const std::array<Eigen::Vector3d, 3>& t1,
                                                   long num, long den) {
  const mpq_class t(num, den);
  const mpq_class s = 1 - t;
  std::array<std::array<mpq_class, 3>, 3> p;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      p[i][j] = s * mpq_class(t0[i][j]) + t * mpq_class(t1[i][j]);
  }
  std::array<mpq_class, 3> e1, e2;
  for (int j = 0; j < 3; ++j) {
    e1[j] = p[1][j] - p[0][j];
    e2[j] = p[2][j] - p[0][j];
  }
  const std::array<mpq_class, 3> n = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                      e1[0] * e2[1] - e1[1] * e2[0]};
  mpq_class largest = 0;
  for (const auto& c : n) {
    if (abs(c) > largest) largest = abs(c);
  }
  if (largest == 0) return std::nullopt;
  Eigen::Vector3d d;
  for (int j = 0; j < 3; ++j) {
    const mpq_class q = n[j] / largest;  // in [-1, 1]: converts without overflow or underflow
    d[j] = q.get_d();
  }
  return d.normalized();
}

}  // namespace clothcd::test
