#pragma once
// Rounding slack of distance evaluations: 1e-12 x max(1, largest coordinate magnitude), far above
// their error (a few ulps of the coordinates), far below any thickness a simulator uses. Shared
// by the distance filter and the distances' lower bounds, which must agree on it.

#include <Eigen/Core>

#include <algorithm>
#include <initializer_list>

namespace clothcd::ccd_detail {

inline double coordinate_slack(std::initializer_list<const Eigen::Vector3d*> points) {
  double m = 1.0;
  for (const Eigen::Vector3d* p : points)
    m = std::max(m, p->cwiseAbs().maxCoeff());
  return 1e-12 * m;
}

}  // namespace clothcd::ccd_detail
