#pragma once
/// @file
/// Discrete proximity: closest points between a point and a triangle, and between two segments.
/// Robust for degenerate input: a triangle collapsed to a segment or a point, zero-length edges
/// and parallel or collinear edges all give a finite, correct answer (never NaN). Finite input is
/// required (std::invalid_argument otherwise).

#include <Eigen/Core>

namespace clothcd {

struct PointTriangleProximity {
  double distance = 0;
  /// Barycentric weights of the closest point on the triangle: w0 f0 + w1 f1 + w2 f2, all >= 0,
  /// summing to 1.
  Eigen::Vector3d weights = Eigen::Vector3d(1, 0, 0);
  Eigen::Vector3d closest = Eigen::Vector3d::Zero();  ///< the closest point on the triangle
};

struct EdgeEdgeProximity {
  double distance = 0;
  /// Closest points ea0 + s (ea1 - ea0) and eb0 + t (eb1 - eb0), s and t in [0, 1].
  double s = 0, t = 0;
  Eigen::Vector3d closest_a = Eigen::Vector3d::Zero(), closest_b = Eigen::Vector3d::Zero();
};

[[nodiscard]] PointTriangleProximity point_triangle_proximity(const Eigen::Vector3d& p,
                                                              const Eigen::Vector3d& f0,
                                                              const Eigen::Vector3d& f1,
                                                              const Eigen::Vector3d& f2);

[[nodiscard]] EdgeEdgeProximity edge_edge_proximity(const Eigen::Vector3d& ea0,
                                                    const Eigen::Vector3d& ea1,
                                                    const Eigen::Vector3d& eb0,
                                                    const Eigen::Vector3d& eb1);

/// Lower bounds on the distances above, for culling before the exact query: the gap between the
/// features' bounding boxes and the distance to the triangle's plane (to the other edge's line
/// for two edges, skipped for slivers and near-parallel edges), less a rounding allowance of
/// 1e-12 x max(1, largest coordinate magnitude). Never above the distance the exact function
/// returns for the same input, and never negative. Finite input is required
/// (std::invalid_argument otherwise).
[[nodiscard]] double point_triangle_distance_lower_bound(const Eigen::Vector3d& p,
                                                         const Eigen::Vector3d& f0,
                                                         const Eigen::Vector3d& f1,
                                                         const Eigen::Vector3d& f2);
[[nodiscard]] double edge_edge_distance_lower_bound(const Eigen::Vector3d& ea0,
                                                    const Eigen::Vector3d& ea1,
                                                    const Eigen::Vector3d& eb0,
                                                    const Eigen::Vector3d& eb1);

/// Lower bound on the distance between two whole triangles a and b, so on every VF and EE
/// distance between them: the larger of their boxes' gap and how far either triangle's plane
/// keeps the other wholly on one side (skipped for slivers), less the same rounding allowance.
/// 0 where it proves nothing (the triangles straddle each other's planes). Finite input is
/// required (std::invalid_argument otherwise).
[[nodiscard]] double triangle_triangle_distance_lower_bound(
    const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
    const Eigen::Vector3d& b0, const Eigen::Vector3d& b1, const Eigen::Vector3d& b2);

/// The exact distance where it is at most `limit`; elsewhere some value above `limit` (the lower
/// bound, when that already exceeds `limit`: the exact query is then skipped). For callers that
/// only compare the distance with a limit. Finite input is required (std::invalid_argument
/// otherwise).
[[nodiscard]] double point_triangle_distance_if_within(const Eigen::Vector3d& p,
                                                       const Eigen::Vector3d& f0,
                                                       const Eigen::Vector3d& f1,
                                                       const Eigen::Vector3d& f2, double limit);
[[nodiscard]] double edge_edge_distance_if_within(const Eigen::Vector3d& ea0,
                                                  const Eigen::Vector3d& ea1,
                                                  const Eigen::Vector3d& eb0,
                                                  const Eigen::Vector3d& eb1, double limit);

/// Closest point parameter of p on segment ab, in [0, 1] (0 for a zero-length segment).
[[nodiscard]] double point_segment_parameter(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                             const Eigen::Vector3d& b);

}  // namespace clothcd
