#pragma once
// Validation of positions at the public boundary, for either input form the detectors accept.

#include <fmt/format.h>
#include <Eigen/Core>

#include <cmath>
#include <span>
#include <string_view>
#include <vector>

#include "clothcd/core/error.hpp"

namespace clothcd::detail {

/// Positions as a caller passed them: a column-major n x 3 matrix or a span of points (no copy of
/// either is made here).
class PointsIn {
 public:
  PointsIn(const Eigen::MatrixXd& m) : matrix_(&m) {}                     // NOLINT: implicit
  PointsIn(std::span<const Eigen::Vector3d> points) : points_(points) {}  // NOLINT: implicit

  [[nodiscard]] const Eigen::MatrixXd* matrix() const { return matrix_; }
  [[nodiscard]] std::span<const Eigen::Vector3d> points() const { return points_; }

 private:
  const Eigen::MatrixXd* matrix_ = nullptr;
  std::span<const Eigen::Vector3d> points_;
};

/// Throws InputError naming the input and the bad vertex unless `in` holds num_vertices finite
/// points (to_points' checks, without the copy).
inline void check_points(PointsIn in, int num_vertices, std::string_view name) {
  if (const Eigen::MatrixXd* m = in.matrix()) {
    if (m->rows() != num_vertices || m->cols() != 3) {
      throw InputError(fmt::format("{}: expected a {} x 3 position matrix, got {} x {}", name,
                                   num_vertices, m->rows(), m->cols()));
    }
    for (int i = 0; i < num_vertices; ++i) {
      if (!m->row(i).allFinite()) {
        throw InputError(fmt::format("{}: vertex {} has a non-finite coordinate", name, i));
      }
    }
    return;
  }
  const auto points = in.points();
  if (points.size() != static_cast<std::size_t>(num_vertices)) {
    throw InputError(fmt::format("{}: expected a {} x 3 position matrix, got {} x 3", name,
                                 num_vertices, points.size()));
  }
  for (int i = 0; i < num_vertices; ++i) {
    if (!points[i].allFinite()) {
      throw InputError(fmt::format("{}: vertex {} has a non-finite coordinate", name, i));
    }
  }
}

/// Calls f(get) with get(i) = point i of `in` (checked by check_points), for either input form:
/// the form is settled once, not per point.
template <class F>
void with_points(PointsIn in, F&& f) {
  if (const Eigen::MatrixXd* m = in.matrix()) {
    f([m](int i) -> Eigen::Vector3d { return m->row(i).transpose(); });
  } else {
    f([p = in.points()](int i) -> Eigen::Vector3d { return p[static_cast<std::size_t>(i)]; });
  }
}

/// Copies the positions into `out`; throws InputError naming the input and the bad vertex.
inline void to_points(PointsIn in, int num_vertices, std::string_view name,
                      std::vector<Eigen::Vector3d>& out) {
  if (const Eigen::MatrixXd* m = in.matrix()) {
    if (m->rows() != num_vertices || m->cols() != 3) {
      throw InputError(fmt::format("{}: expected a {} x 3 position matrix, got {} x {}", name,
                                   num_vertices, m->rows(), m->cols()));
    }
    out.resize(num_vertices);
    for (int i = 0; i < num_vertices; ++i)
      out[i] = m->row(i).transpose();
  } else {
    const auto points = in.points();
    if (points.size() != static_cast<std::size_t>(num_vertices)) {
      throw InputError(fmt::format("{}: expected a {} x 3 position matrix, got {} x 3", name,
                                   num_vertices, points.size()));
    }
    out.assign(points.begin(), points.end());
  }
  for (int i = 0; i < num_vertices; ++i) {
    if (!out[i].allFinite()) {
      throw InputError(fmt::format("{}: vertex {} has a non-finite coordinate", name, i));
    }
  }
}

}  // namespace clothcd::detail
