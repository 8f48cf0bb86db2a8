// Which vertices moved since an earlier call: CCD passes repeat with a few vertices' motion
// changed, and what depends on positions alone (feature boxes, BVH refits) need only be redone
// over those.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace clothcd::detail {

/// Compares the positions at t0 and t1 with the copies `seen0` / `seen1` kept from an earlier
/// call and brings the copies up to date. Returns one flag per vertex, set where either position
/// changed; nothing when the copies are of another size (first call, or cleared to start over):
/// then every vertex counts as moved.
inline std::optional<std::vector<std::uint8_t>> moved_vertices(
    std::vector<Eigen::Vector3d>& seen0, std::vector<Eigen::Vector3d>& seen1,
    std::span<const Eigen::Vector3d> x0, std::span<const Eigen::Vector3d> x1) {
  if (seen0.size() != x0.size() || seen1.size() != x1.size() || x0.size() != x1.size()) {
    seen0.assign(x0.begin(), x0.end());
    seen1.assign(x1.begin(), x1.end());
    return std::nullopt;
  }
  std::vector<std::uint8_t> moved(x0.size(), 0);
  for (std::size_t i = 0; i < x0.size(); ++i) {
    if (x0[i] != seen0[i] || x1[i] != seen1[i]) {
      moved[i] = 1;
      seen0[i] = x0[i];
      seen1[i] = x1[i];
    }
  }
  return moved;
}

}  // namespace clothcd::detail
