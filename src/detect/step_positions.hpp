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
  /// Validates the positions of a call (v1 = v0 for a static one), flags the vertices where
  /// either differs from the previous call's and copies them in place of those. Throws
  /// InputError (the state is then unchanged).
  void update(PointsIn p0, PointsIn p1, int num_vertices, std::string_view name0,
              std::string_view name1) {
    check_points(p0, num_vertices, name0);
    check_points(p1, num_vertices, name1);
    commit(p0, p1, num_vertices);
  }
  void update_static(PointsIn p, int num_vertices, std::string_view name) {
    check_points(p, num_vertices, name);
    commit(p, p, num_vertices);
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
  // Compared and overwritten vertex by vertex: no second copy of the positions (on a mesh of
  // millions of vertices, each copy is tens of MiB). Each vertex is read before it is written, so
  // inputs that are this object's own positions are read right.
  void commit(PointsIn p0, PointsIn p1, int n) {
    with_points(p0, [&](auto&& get0) {
      with_points(p1, [&](auto&& get1) { commit_from(get0, get1, n); });
    });
    ++call_;
  }
  template <class Get0, class Get1>
  void commit_from(const Get0& get0, const Get1& get1, int n) {
    const auto count = static_cast<std::size_t>(n);
    have_changed_ = x0_.size() == count;
    if (!have_changed_) {
      x0_.resize(count);
      x1_.resize(count);
      for (int i = 0; i < n; ++i) {
        x0_[i] = get0(i);
        x1_[i] = get1(i);
      }
      return;
    }
    changed_.resize(count);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d a = get0(i), b = get1(i);
      changed_[i] = (a != x0_[i] || b != x1_[i]) ? 1 : 0;
      x0_[i] = a;
      x1_[i] = b;
    }
  }

  std::vector<Eigen::Vector3d> x0_, x1_;
  std::vector<std::uint8_t> changed_;
  bool have_changed_ = false;
  std::uint64_t call_ = 0;
};

}  // namespace clothcd::detail
