// next_up / next_down against std::nextafter: the boxes must round exactly as before.
#include "clothcd/core/ulp.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace clothcd::detail {
namespace {

template <class F>
std::vector<F> special_values() {
  using L = std::numeric_limits<F>;
  return {F(0),         -F(0),     L::denorm_min(), -L::denorm_min(), L::min(), -L::min(),
          L::max(),     -L::max(), L::infinity(),   -L::infinity(),   F(1),     F(-1),
          L::epsilon(), F(1e-5),   F(-3.75),        F(123456.5)};
}

// Same bits, except that any NaN matches any NaN.
template <class F, class U>
void expect_same(F got, F want, F x) {
  if (std::isnan(want)) {
    EXPECT_TRUE(std::isnan(got)) << x;
  } else {
    EXPECT_EQ(std::bit_cast<U>(got), std::bit_cast<U>(want))
        << "x = " << x << " got " << got << " want " << want;
  }
}

template <class F, class U>
void check_against_libm() {
  using L = std::numeric_limits<F>;
  std::vector<F> xs = special_values<F>();
  xs.push_back(L::quiet_NaN());
  std::mt19937_64 rng(7);
  for (int i = 0; i < 200000; ++i)
    xs.push_back(std::bit_cast<F>(static_cast<U>(rng())));  // every exponent, both signs
  for (F x : xs) {
    expect_same<F, U>(next_up(x), std::nextafter(x, L::infinity()), x);
    expect_same<F, U>(next_down(x), std::nextafter(x, -L::infinity()), x);
  }
}

TEST(Ulp, DoubleMatchesNextafterOnSpecialAndRandomValues) {
  check_against_libm<double, std::uint64_t>();
}

TEST(Ulp, FloatMatchesNextafterOnSpecialAndRandomValues) {
  check_against_libm<float, std::uint32_t>();
}

TEST(Ulp, StepsAreOneUnitInTheLastPlace) {
  EXPECT_EQ(next_up(1.0), 1.0 + std::numeric_limits<double>::epsilon());
  EXPECT_EQ(next_down(1.0f), 1.0f - std::numeric_limits<float>::epsilon() / 2);
  EXPECT_EQ(next_up(-std::numeric_limits<double>::denorm_min()), 0.0);
  EXPECT_TRUE(std::signbit(next_up(-std::numeric_limits<double>::denorm_min())));
}

}  // namespace
}  // namespace clothcd::detail
