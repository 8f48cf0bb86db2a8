#pragma once
// Validation of position matrices at the public boundary.

#include <fmt/format.h>
#include <Eigen/Core>

#include <cmath>
#include <string_view>
#include <vector>

#include "clothcd/core/error.hpp"

namespace clothcd::detail {

/// Rows of an n x 3 matrix as points; throws InputError naming the matrix and the bad vertex.
inline void to_points(const Eigen::MatrixXd& m, int num_vertices, std::string_view name,
                      std::vector<Eigen::Vector3d>& out) {
  if (m.rows() != num_vertices || m.cols() != 3) {
    throw InputError(fmt::format("{}: expected a {} x 3 position matrix, got {} x {}", name,
                                 num_vertices, m.rows(), m.cols()));
  }
  out.resize(num_vertices);
  for (int i = 0; i < num_vertices; ++i) {
    out[i] = m.row(i).transpose();
    if (!out[i].allFinite()) {
      throw InputError(fmt::format("{}: vertex {} has a non-finite coordinate", name, i));
    }
  }
}

}  // namespace clothcd::detail
