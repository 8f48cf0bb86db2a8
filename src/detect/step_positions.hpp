#pragma once
// The positions of a detector's calls and which vertices changed from one call to the next,
// computed once per call: the BVH refit and the feature boxes redo only what depends on the
// changed vertices (a simulator's repeated CCD passes move a few hundred of them).

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "detect/positions.hpp"

namespace clothcd::detail {

class StepPositions {
 public:
  /// Validates and copies the positions of a call (v1 = v0 for a static one) and flags the
  /// vertices where either differs from the previous call's. Throws InputError (the state is
  /// then unchanged).
  void update(PointsIn p0, PointsIn p1, int num_vertices, std::string_view name0,
              std::string_view name1) {
    to_points(p0, num_vertices, name0, next0_);
    to_points(p1, num_vertices, name1, next1_);
    commit();
  }
  void update_static(PointsIn p, int num_vertices, std::string_view name) {
    to_points(p, num_vertices, name, next0_);
    next1_ = next0_;
    commit();
  }

  [[nodiscard]] const std::vector<Eigen::Vector3d>& x0() const { return x0_; }
  [[nodiscard]] const std::vector<Eigen::Vector3d>& x1() const { return x1_; }
  /// Number of the current call (1 after the first).
  [[nodiscard]] std::uint64_t call() const { return call_; }
  /// The flags of the vertices that changed since call `since`, when that is the previous call;
  /// empty (every vertex counts as changed) otherwise.
  [[nodiscard]] std::span<const std::uint8_t> changed_since(std::uint64_t since) const {
    if (!have_changed_ || since + 1 != call_) return {};
    return changed_;
  }

 private:
  void commit() {
    have_changed_ = x0_.size() == next0_.size();
    if (have_changed_) {
      changed_.resize(next0_.size());
      for (std::size_t i = 0; i < next0_.size(); ++i)
        changed_[i] = (next0_[i] != x0_[i] || next1_[i] != x1_[i]) ? 1 : 0;
    }
    std::swap(x0_, next0_);
    std::swap(x1_, next1_);
    ++call_;
  }

  std::vector<Eigen::Vector3d> x0_, x1_, next0_, next1_;
  std::vector<std::uint8_t> changed_;
  bool have_changed_ = false;
  std::uint64_t call_ = 0;
};

}  // namespace clothcd::detail
