#pragma once
// Internal: the Bvh refits with optimal node cones, the reference the cone policies are measured
// against (docs/cones.md). Every internal node gets the minimal cone of its descendant leaves'
// normal control directions, from exact leaf caps, instead of RefitOptions::policy's merges; a
// node costs time linear in its triangles, so a refit takes seconds on 100K triangles. Research
// only: clothcd/research/refit.hpp offers them, and the research self detector runs them through
// the detector's refit. Each is the Bvh refit of the same name otherwise, incremental forms
// included.

#include <Eigen/Core>

#include <cstdint>
#include <span>

#include "clothcd/bvh/bvh.hpp"

namespace clothcd::detail {

struct OptimalCones {
  static void refit(Bvh& bvh, std::span<const Eigen::Vector3d> v_t0,
                    std::span<const Eigen::Vector3d> v_t1, const RefitOptions& options) {
    bvh.refit_with(v_t0, v_t1, options, true);
  }
  static void refit_changed(Bvh& bvh, std::span<const Eigen::Vector3d> v_t0,
                            std::span<const Eigen::Vector3d> v_t1, const RefitOptions& options) {
    bvh.refit_changed_with(v_t0, v_t1, options, true);
  }
  static void refit_moved(Bvh& bvh, std::span<const Eigen::Vector3d> v_t0,
                          std::span<const Eigen::Vector3d> v_t1, const RefitOptions& options,
                          std::span<const std::uint8_t> moved) {
    bvh.refit_moved_with(v_t0, v_t1, options, moved, true);
  }
  /// Static boxes and cones at the positions v.
  static void refit(Bvh& bvh, std::span<const Eigen::Vector3d> v, const RefitOptions& options) {
    bvh.refit_static_with(v, options, true);
  }
};

}  // namespace clothcd::detail
