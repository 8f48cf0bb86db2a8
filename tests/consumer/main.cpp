// A downstream program that uses the installed clothcd package.
#include <clothcd/cone.hpp>

#include <cstdio>

int main() {
  const clothcd::NormalCone a{Eigen::Vector3d::UnitZ(), 0.1};
  const clothcd::NormalCone b{Eigen::Vector3d(0, 1, 1).normalized(), 0.2};
  const auto m = clothcd::merge_tight(a, b);
  std::printf("merged half-angle %.6f saturated %d\n", m.half_angle, int(m.saturated()));
  return m.saturated() ? 1 : 0;
}
