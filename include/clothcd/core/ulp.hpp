#pragma once
/// @file
/// The neighbouring floating-point values, as std::nextafter toward +/- infinity gives them, but
/// inline: the boxes of every refit and swept-box pass round outwards with them
/// (clothcd/bvh/aabb.hpp), and the libm call cost about 5% of a simulation substep.

#include <bit>
#include <cstdint>
#include <limits>

namespace clothcd::detail {

template <class F, class U>
constexpr F step_up(F x) {
  static_assert(sizeof(F) == sizeof(U));
  if (x != x || x == std::numeric_limits<F>::infinity()) return x;  // NaN, +inf
  if (x == F(0)) return std::numeric_limits<F>::denorm_min();       // +0 and -0 alike
  const U bits = std::bit_cast<U>(x);
  // Positive values grow with their bit pattern, negative ones shrink toward zero.
  return std::bit_cast<F>(x > F(0) ? U(bits + 1) : U(bits - 1));
}

template <class F, class U>
constexpr F step_down(F x) {
  return -step_up<F, U>(-x);
}

/// std::nextafter(x, +inf) and std::nextafter(x, -inf) for double and float.
constexpr double next_up(double x) {
  return step_up<double, std::uint64_t>(x);
}
constexpr double next_down(double x) {
  return step_down<double, std::uint64_t>(x);
}
constexpr float next_up(float x) {
  return step_up<float, std::uint32_t>(x);
}
constexpr float next_down(float x) {
  return step_down<float, std::uint32_t>(x);
}

}  // namespace clothcd::detail
