#pragma once
// Vertices tied by a stitch: the collision stage and the intersection count ignore contacts
// between them (a seam's two sides touch by design).

#include <algorithm>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim::detail {

class SeamLinks {
 public:
  SeamLinks() = default;
  /// `pairs`: ClothModel::seam_links() (any order).
  SeamLinks(int num_vertices, std::span<const std::pair<int, int>> pairs) : links_(num_vertices) {
    for (auto [u, w] : pairs) {
      links_[u].push_back(w);
      links_[w].push_back(u);
    }
    for (auto& l : links_) {
      std::sort(l.begin(), l.end());
      l.erase(std::unique(l.begin(), l.end()), l.end());
    }
  }
  /// True when u == v or the seam links tie them.
  [[nodiscard]] bool linked(int u, int v) const {
    if (u == v) return true;
    if (links_.empty()) return false;
    const auto& l = links_[u];
    return std::binary_search(l.begin(), l.end(), v);
  }
  /// True when some vertex of `a` is linked to some vertex of `b`.
  template <class A, class B>
  [[nodiscard]] bool any_linked(const A& a, const B& b) const {
    for (int u : a) {
      for (int v : b) {
        if (linked(u, v)) return true;
      }
    }
    return false;
  }

 private:
  std::vector<std::vector<int>> links_;
};

}  // namespace clothcd::sim::detail
