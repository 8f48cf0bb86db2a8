#pragma once
// Collisions an unculled run finds and another run of the same step does not (both sorted), as
// the demo and `detect --table` report them.

#include <algorithm>
#include <cstddef>
#include <iterator>
#include <utility>
#include <vector>

#include "clothcd/detect/types.hpp"

namespace clothcd::cli {

inline std::size_t missed_against(const DetectResult& none, const DetectResult& r) {
  std::vector<VertexFaceCollision> vf;
  std::vector<EdgeEdgeCollision> ee;
  auto vf_key = [](const VertexFaceCollision& x, const VertexFaceCollision& y) {
    return std::pair(x.vertex, x.face) < std::pair(y.vertex, y.face);
  };
  auto ee_key = [](const EdgeEdgeCollision& x, const EdgeEdgeCollision& y) {
    return std::pair(x.edge_a, x.edge_b) < std::pair(y.edge_a, y.edge_b);
  };
  std::set_difference(none.vf.begin(), none.vf.end(), r.vf.begin(), r.vf.end(),
                      std::back_inserter(vf), vf_key);
  std::set_difference(none.ee.begin(), none.ee.end(), r.ee.begin(), r.ee.end(),
                      std::back_inserter(ee), ee_key);
  return vf.size() + ee.size();
}

}  // namespace clothcd::cli
