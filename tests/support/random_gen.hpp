#pragma once
// A seeded generator of the random CCD queries' coordinates, shared by the tests that draw them
// (the same seed gives the same numbers on every platform's mt19937_64).

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <random>

namespace clothcd::test {

struct Gen {
  using V = Eigen::Vector3d;
  std::mt19937_64 rng;
  explicit Gen(std::uint64_t seed) : rng(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(rng); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<>(lo, hi)(rng); }
  V vec(double s) { return V(uniform(-s, s), uniform(-s, s), uniform(-s, s)); }
  V grid(int k) { return V(integer(-k, k), integer(-k, k), integer(-k, k)); }
  // Log-uniform scale in [2^-30, 2^30].
  double scale() { return std::ldexp(1.0, integer(-30, 30)); }
};

}  // namespace clothcd::test
