#pragma once
// The unchecked forms of the public proximity functions (clothcd/ccd/proximity.hpp), for callers
// that have checked their input once and evaluate many distances on it (the distance filter):
// every point must be finite.

#include <Eigen/Core>

#include "clothcd/ccd/proximity.hpp"

namespace clothcd::ccd_detail {

[[nodiscard]] PointTriangleProximity point_triangle_closest(const Eigen::Vector3d& p,
                                                            const Eigen::Vector3d& f0,
                                                            const Eigen::Vector3d& f1,
                                                            const Eigen::Vector3d& f2);
[[nodiscard]] EdgeEdgeProximity edge_edge_closest(const Eigen::Vector3d& ea0,
                                                  const Eigen::Vector3d& ea1,
                                                  const Eigen::Vector3d& eb0,
                                                  const Eigen::Vector3d& eb1);
[[nodiscard]] double point_triangle_bound(const Eigen::Vector3d& p, const Eigen::Vector3d& f0,
                                          const Eigen::Vector3d& f1, const Eigen::Vector3d& f2);
[[nodiscard]] double edge_edge_bound(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                     const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1);

/// point_triangle_distance_if_within and edge_edge_distance_if_within without the input check,
/// for the detectors' proximity queries (their positions are checked once per call).
[[nodiscard]] double point_triangle_within(const Eigen::Vector3d& p, const Eigen::Vector3d& f0,
                                           const Eigen::Vector3d& f1, const Eigen::Vector3d& f2,
                                           double limit);
[[nodiscard]] double edge_edge_within(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                      const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1,
                                      double limit);

}  // namespace clothcd::ccd_detail
