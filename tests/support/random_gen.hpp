#pragma once
// A seeded generator of random coordinates and faces, shared by the tests that draw them
// (the same seed gives the same numbers on every platform's mt19937_64).

#include <Eigen/Core>

#include <array>
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
  // Three distinct vertex ids in [0, nv), in the order drawn.
  std::array<int, 3> face(int nv) {
    std::array<int, 3> t{};
    t[0] = integer(0, nv - 1);
    do {
      t[1] = integer(0, nv - 1);
    } while (t[1] == t[0]);
    do {
      t[2] = integer(0, nv - 1);
    } while (t[2] == t[0] || t[2] == t[1]);
    return t;
  }
  // Log-uniform scale in [2^-30, 2^30].
  double scale() { return std::ldexp(1.0, integer(-30, 30)); }
};

}  // namespace clothcd::test
