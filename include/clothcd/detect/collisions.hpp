#pragma once
/// @file
/// The collisions the detectors report: a vertex hitting a face, two edges touching.

#include "clothcd/mesh/topology.hpp"

namespace clothcd {

/// Vertex `vertex` hits face `face` (vertex ids `face_vertices`) at time `toi` in [0, 1].
struct VertexFaceCollision {
  int vertex = -1;
  int face = -1;
  Face face_vertices{};
  double toi = 1.0;
  friend bool operator==(const VertexFaceCollision&, const VertexFaceCollision&) = default;
};

/// Edge `edge_a` < `edge_b` (Topology edge ids) touch at time `toi`.
struct EdgeEdgeCollision {
  int edge_a = -1;
  int edge_b = -1;
  Edge edge_a_vertices{};
  Edge edge_b_vertices{};
  double toi = 1.0;
  friend bool operator==(const EdgeEdgeCollision&, const EdgeEdgeCollision&) = default;
};

}  // namespace clothcd
