#include "ccd/motion.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace clothcd::ccd_detail {

Motion make_motion(const std::array<const Eigen::Vector3d*, 8>& points) {
  double m = 0;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d& p = *points[i];
    if (!p.allFinite()) {
      throw std::invalid_argument(
          fmt::format("CCD query point {} is not finite ({}, {}, {})", i, p.x(), p.y(), p.z()));
    }
    m = std::max(m, p.cwiseAbs().maxCoeff());
  }
  Motion out;
  // 2^-e with m * 2^-e in [0.5, 1); m == 0 leaves the (all-zero) query as it is.
  int e = 0;
  if (m > 0) std::frexp(m, &e);
  out.scale = std::ldexp(1.0, -e);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  out.max_abs.setZero();
  for (int k = 0; k < 4; ++k) {
    out.x0[k] = *points[k] * out.scale;
    out.x1[k] = *points[k + 4] * out.scale;
    for (const Eigen::Vector3d* p : {&out.x0[k], &out.x1[k]}) {
      lo = lo.cwiseMin(*p);
      hi = hi.cwiseMax(*p);
      out.max_abs = out.max_abs.cwiseMax(p->cwiseAbs());
    }
  }
  out.extent = (hi - lo).maxCoeff();
  return out;
}

}  // namespace clothcd::ccd_detail
