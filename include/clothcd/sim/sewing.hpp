#pragma once
/// @file
/// Seam recovery for garments whose stitch list is missing (docs/simulator.md 0): tie every
/// boundary vertex to the closest point of another panel's boundary edge within `max_distance`.

#include <vector>

#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim {

/// Panels are the edge-connected components of the faces. Output sorted by vertex.
[[nodiscard]] std::vector<Stitch> recover_stitches(const std::vector<Vec3>& positions,
                                                   const std::vector<Face>& faces,
                                                   double max_distance);

}  // namespace clothcd::sim
