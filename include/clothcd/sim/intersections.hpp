#pragma once
/// @file
/// Intersecting triangle pairs of a frame (docs/simulator.md 3.5): the cloth with itself (pairs
/// sharing a vertex or tied by a seam link are skipped) and the cloth with the body. A BVH
/// prefilter (clothcd::Bvh, static boxes) feeds a discrete triangle-triangle test.

#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/mesh/topology.hpp"
#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim {

/// True when the triangles cross: an edge of one passes strictly through the plane of the other,
/// inside or on the border of that triangle. Coplanar and merely touching pairs (a vertex exactly
/// in the other's plane) do not count; the predicates are evaluated in double precision.
[[nodiscard]] bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2,
                                       const Vec3& b0, const Vec3& b1, const Vec3& b2);

class IntersectionCounter {
 public:
  /// `body_faces` may be empty (no body); `links` are the cloth model's seam links (vertex pairs
  /// that count as one point, ClothModel::seam_links()).
  IntersectionCounter(const Topology& cloth, std::span<const std::pair<int, int>> links,
                      const std::vector<Face>& body_faces, int body_vertices);
  ~IntersectionCounter();

  /// Intersecting non-adjacent, non-stitched cloth triangle pairs (f < g), sorted.
  [[nodiscard]] std::vector<std::pair<int, int>> self_pairs(std::span<const Vec3> x);
  /// Intersecting (cloth face, body face) pairs, sorted.
  [[nodiscard]] std::vector<std::pair<int, int>> body_pairs(std::span<const Vec3> x,
                                                            std::span<const Vec3> body);

  /// The same by testing every pair (test oracle).
  [[nodiscard]] std::vector<std::pair<int, int>> self_pairs_brute_force(
      std::span<const Vec3> x) const;
  [[nodiscard]] std::vector<std::pair<int, int>> body_pairs_brute_force(
      std::span<const Vec3> x, std::span<const Vec3> body) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothcd::sim
