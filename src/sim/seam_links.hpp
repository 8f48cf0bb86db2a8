#pragma once
// Vertices tied by a stitch: the collision stage and the intersection count ignore contacts
// between them (a seam's two sides touch by design).

#include <algorithm>
#include <span>
#include <vector>

#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim::detail {

class SeamLinks {
 public:
  SeamLinks() = default;
  SeamLinks(int num_vertices, std::span<const StitchTerm> stitches) : links_(num_vertices) {
    for (const StitchTerm& s : stitches) {
      for (int i = 0; i < s.count; ++i) {
        for (int j = 0; j < s.count; ++j) {
          if (i != j) links_[s.v[i]].push_back(s.v[j]);
        }
      }
    }
    for (auto& l : links_) {
      std::sort(l.begin(), l.end());
      l.erase(std::unique(l.begin(), l.end()), l.end());
    }
  }
  /// True when u == v or a stitch ties them.
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
