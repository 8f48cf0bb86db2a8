#pragma once
/// @file
/// Sewing garment panels into one mesh. Garment files list each panel as its own mesh: vertices
/// along a seam coincide but are not shared, and a seam may join edges of different resolution
/// (T-junctions). A detector must know which triangles are neighbours across a seam, so sewing
/// welds coincident vertices and splits edges at T-junctions; the map from original to sewn vertex
/// ids lets results be reported in the original numbering.

#include <span>
#include <vector>

#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/triangle_mesh.hpp"

namespace clothcd {

/// Counts before and after sewing (components are edge-connected, see Topology).
struct SewingReport {
  int components_before = 0, components_after = 0;
  int boundary_edges_before = 0, boundary_edges_after = 0;
  int nonmanifold_edges_before = 0, nonmanifold_edges_after = 0;
  int vertices_welded = 0;  ///< vertices merged into another (input count - output count)
  int edges_split = 0;      ///< T-junction splits: one per (edge, inserted vertex)
  int faces_dropped = 0;    ///< faces that collapsed when their corners were welded
};

/// A sewn mesh. Vertices keep their relative order; `vertex_map[original id]` is the new id.
struct SewnMesh {
  TriangleMesh mesh;
  std::vector<int> vertex_map;
  SewingReport report;
};

/// Merges vertices within `tolerance` (Euclidean) of each other, transitively: each cluster
/// becomes its smallest original id, at that vertex's position. Faces that then repeat a vertex
/// are dropped. Deterministic (a uniform grid of cell `tolerance`; the order of the input decides).
/// Throws InputError for a non-positive or non-finite tolerance, or one too small for the
/// coordinates' magnitude.
[[nodiscard]] SewnMesh weld(const TriangleMesh& mesh, double tolerance);

/// weld(), then T-junction conforming: a boundary vertex within `tolerance` of the interior of a
/// boundary edge (of a face not containing it), and farther than `tolerance` from both ends,
/// splits that edge and its triangle; repeated until none is left.
[[nodiscard]] SewnMesh sew(const TriangleMesh& mesh, double tolerance);

/// Sewing from explicit ties (stage.obj `stitch` lines, vertex i tied to (1-r) x_j + r x_k):
/// i is welded to j when r <= r_tolerance, to k when r >= 1 - r_tolerance, and otherwise splits
/// edge (j, k) at i. Throws InputError naming the stitch when an index is out of range or j, k
/// share no edge.
[[nodiscard]] SewnMesh sew_stitches(const TriangleMesh& mesh, std::span<const Stitch> stitches,
                                    double r_tolerance = 1e-6);

}  // namespace clothcd
