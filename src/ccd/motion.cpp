#include "ccd/motion.hpp"

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <fmt/format.h>

namespace clothcd::ccd_detail {

namespace {

// The scaled positions and their extents. Plain per-coordinate loops (the same products, minima
// and maxima, in the same order, as vector expressions): this runs once for every query past the
// NP filter.
template <class Scale>
void fill_scaled(Motion& out, const std::array<const Eigen::Vector3d*, 8>& points, Scale scale) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  double top[3] = {0, 0, 0};
  for (int k = 0; k < 4; ++k) {
    for (int a = 0; a < 3; ++a) {
      const double p = scale((*points[k])[a]), q = scale((*points[k + 4])[a]);
      out.x0[k][a] = p;
      out.x1[k][a] = q;
      lo[a] = std::min(std::min(lo[a], p), q);
      hi[a] = std::max(std::max(hi[a], p), q);
      top[a] = std::max(std::max(top[a], std::abs(p)), std::abs(q));
    }
  }
  out.max_abs = Eigen::Vector3d(top[0], top[1], top[2]);
  out.extent = std::max(std::max(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
}

}  // namespace

Motion make_motion(const std::array<const Eigen::Vector3d*, 8>& points) {
  double m = 0;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d& p = *points[i];
    const double ax = std::abs(p.x()), ay = std::abs(p.y()), az = std::abs(p.z());
    if (!(ax <= DBL_MAX && ay <= DBL_MAX && az <= DBL_MAX)) {  // NaN or infinite
      throw std::invalid_argument(
          fmt::format("CCD query point {} is not finite ({}, {}, {})", i, p.x(), p.y(), p.z()));
    }
    m = std::max(m, std::max(std::max(ax, ay), az));
  }
  Motion out;
  out.largest = m;
  out.scale_exponent = -binade_exponent(m);
  if (out.scale_exponent <= DBL_MAX_EXP - 1) {
    const double scale = out.scale = power_of_two(out.scale_exponent);
    fill_scaled(out, points, [scale](double x) { return x * scale; });
  } else {
    // Every coordinate is below 2^-1023, and 2^scale_exponent is no double: std::ldexp scales
    // them, exactly (the results are normal).
    out.scale = 0;
    const int k = out.scale_exponent;
    fill_scaled(out, points, [k](double x) { return std::ldexp(x, k); });
  }
  return out;
}

int binade_exponent(double m) {
  // Read off the bits of a normal m; std::frexp elsewhere.
  if (m >= DBL_MIN && m <= DBL_MAX)
    return static_cast<int>(std::bit_cast<std::uint64_t>(m) >> 52) - 1022;
  int e = 0;
  if (m > 0) std::frexp(m, &e);
  return e;
}

double power_of_two(int k) {
  // Built from bits where 2^k is normal; ldexp elsewhere.
  if (k >= DBL_MIN_EXP - 1 && k <= DBL_MAX_EXP - 1) {
    return std::bit_cast<double>(static_cast<std::uint64_t>(1023 + k) << 52);
  }
  return std::ldexp(1.0, k);
}

double inverse_binade(double m) {
  // The common case straight from the exponent bits: m normal and below 2^1021 (biased exponent
  // 1..2044), so that 2^-e is a normal double too (the settle calls this once per kept query).
  const std::uint64_t e = std::bit_cast<std::uint64_t>(m) >> 52;
  if (e >= 1 && e <= 2044) return std::bit_cast<double>((2045 - e) << 52);
  return power_of_two(-binade_exponent(m));
}

}  // namespace clothcd::ccd_detail
