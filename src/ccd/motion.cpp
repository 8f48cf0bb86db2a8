#include "ccd/motion.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace clothcd::ccd_detail {

Motion make_motion(const std::array<const Eigen::Vector3d*, 8>& points) {
  // Loops over plain coordinates: the operations of Eigen's coefficient-wise min, max and abs
  // (std::min / std::max, same argument order), without the expressions' overhead; most queries
  // of a detection step that pass the NP filter come here.
  double m = 0;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d& p = *points[i];
    const double a0 = std::abs(p[0]), a1 = std::abs(p[1]), a2 = std::abs(p[2]);
    if (!(a0 <= DBL_MAX && a1 <= DBL_MAX && a2 <= DBL_MAX)) {  // NaN or infinite
      throw std::invalid_argument(
          fmt::format("CCD query point {} is not finite ({}, {}, {})", i, p.x(), p.y(), p.z()));
    }
    m = std::max(m, std::max(std::max(a0, a1), a2));
  }
  Motion out;
  // 2^-e with m * 2^-e in [0.5, 1); m == 0 leaves the (all-zero) query as it is.
  int e = 0;
  if (m > 0) std::frexp(m, &e);
  out.scale = std::ldexp(1.0, -e);
  double lo[3], hi[3], mx[3];
  for (int c = 0; c < 3; ++c) {
    lo[c] = INFINITY;
    hi[c] = -INFINITY;
    mx[c] = 0.0;
  }
  const auto extend = [&](const Eigen::Vector3d& q) {
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], q[c]);
      hi[c] = std::max(hi[c], q[c]);
      mx[c] = std::max(mx[c], std::abs(q[c]));
    }
  };
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d& p0 = *points[k];
    const Eigen::Vector3d& p1 = *points[k + 4];
    for (int c = 0; c < 3; ++c) {
      out.x0[k][c] = p0[c] * out.scale;
      out.x1[k][c] = p1[c] * out.scale;
    }
    extend(out.x0[k]);
    extend(out.x1[k]);
  }
  out.max_abs = Eigen::Vector3d(mx[0], mx[1], mx[2]);
  out.extent =
      (Eigen::Vector3d(hi[0], hi[1], hi[2]) - Eigen::Vector3d(lo[0], lo[1], lo[2])).maxCoeff();
  return out;
}

}  // namespace clothcd::ccd_detail
