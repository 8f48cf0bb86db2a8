#pragma once
// Orphan feature pairs (docs/algorithms.md 6.3): VF and EE pairs all of whose triangle pairs share
// a vertex. The traversal never visits adjacent triangle pairs, so these are tested on their own.

#include <utility>
#include <vector>

#include "clothcd/mesh/topology.hpp"

namespace clothcd::detail {

struct Orphans {
  std::vector<std::pair<int, int>> vf;  ///< (vertex, face), sorted
  std::vector<std::pair<int, int>> ee;  ///< (edge, edge) with first < second, sorted
};

[[nodiscard]] Orphans find_orphans(const Topology& topo);

}  // namespace clothcd::detail
