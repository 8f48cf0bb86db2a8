// moved_vertices: nothing to compare on the first call, then exactly the vertices whose t0 or t1
// position changed.
#include "core/moved_vertices.hpp"

#include <gtest/gtest.h>

namespace clothcd::detail {
namespace {

TEST(MovedVertices, FlagsExactlyTheVerticesWhosePositionsChanged) {
  std::vector<Eigen::Vector3d> seen0, seen1;
  std::vector<Eigen::Vector3d> x0(5, Eigen::Vector3d::Zero()), x1(5, Eigen::Vector3d::Ones());
  EXPECT_FALSE(moved_vertices(seen0, seen1, x0, x1).has_value());  // first call: all moved
  EXPECT_EQ(*moved_vertices(seen0, seen1, x0, x1), (std::vector<std::uint8_t>{0, 0, 0, 0, 0}));
  x0[1].x() = 1e-300;  // the smallest change counts
  x1[3].z() = 2.0;
  EXPECT_EQ(*moved_vertices(seen0, seen1, x0, x1), (std::vector<std::uint8_t>{0, 1, 0, 1, 0}));
  EXPECT_EQ(*moved_vertices(seen0, seen1, x0, x1), (std::vector<std::uint8_t>{0, 0, 0, 0, 0}));
  x0.pop_back();
  x1.pop_back();
  EXPECT_FALSE(moved_vertices(seen0, seen1, x0, x1).has_value());  // another size: start over
}

}  // namespace
}  // namespace clothcd::detail
