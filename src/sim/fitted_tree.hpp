#pragma once
// A box-only BVH kept fit to a deforming mesh. A clothcd BVH is built once and refit; refit to
// shapes far from the build's, its boxes loosen and every query visits more node pairs
// (docs/simulator.md 3.6). This one is built afresh from the current shape when the refit
// boxes have loosened kLooser times past their fit at the last build (Bvh::box_area_ratio()).
// What a query finds does not depend on the tree, only how long it takes.

#include <span>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim::detail {

class FittedTree {
 public:
  /// Rebuild past this growth of the box area ratio since the last build.
  static constexpr double kLooser = 1.5;
  /// Whether a tree whose box area ratio was `fit` right after its build has loosened enough to
  /// rebuild at `ratio` (never when either is NaN).
  [[nodiscard]] static bool loosened(double ratio, double fit) { return ratio > kLooser * fit; }

  FittedTree() = default;
  /// The topology must outlive the tree. Nothing is built before the first refit.
  explicit FittedTree(const Topology& topology) : topology_(&topology) {}

  /// Static boxes at x (Bvh::refit), the tree first rebuilt on x when it has loosened (or was
  /// never built).
  void refit(std::span<const Vec3> x, const RefitOptions& options) {
    if (builds_ > 0) {
      bvh_.refit(x, options);
      if (!loosened(bvh_.box_area_ratio(), built_ratio_)) return;
    }
    bvh_ = Bvh::boxes_only(*topology_, x, BvhBuild::Spatial);
    bvh_.refit(x, options);
    built_ratio_ = bvh_.box_area_ratio();
    ++builds_;
  }

  /// The tree, for swept refits after refit(x) and for traversals.
  [[nodiscard]] Bvh& bvh() { return bvh_; }
  [[nodiscard]] const Bvh& bvh() const { return bvh_; }
  /// How many times it was built.
  [[nodiscard]] int builds() const { return builds_; }

 private:
  const Topology* topology_ = nullptr;
  Bvh bvh_;
  double built_ratio_ = 0.0;
  int builds_ = 0;
};

}  // namespace clothcd::sim::detail
