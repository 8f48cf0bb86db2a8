#pragma once
/// @file
/// Intersecting triangle pairs of a frame (docs/simulator.md 3.5): the cloth with itself (pairs
/// sharing a vertex or tied by a seam link are skipped) and the cloth with the body. A BVH
/// prefilter (clothcd::Bvh, static boxes) feeds a discrete triangle-triangle test.

#include <cstdint>
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

/// What repair_self_crossings did.
struct CrossingRepair {
  long long pairs_before = 0, pairs_after = 0;  ///< intersecting self pairs
  int moves = 0;                                ///< vertex moves kept
  double largest_move = 0.0;                    ///< m
};

/// Undoes self crossings of a cloth's starting shape (an input drape whose panels cross at a
/// seam: the collision stage leaves crossing pairs out and nothing else would undo them). For
/// each crossing pair, the vertex that lies alone on its side of the other triangle's plane (of
/// the pair's two such vertices, the nearer to its plane first) moves through that plane to
/// `margin` beyond it along its normal, which separates the pair; vertices flagged in `fixed`
/// never move. A move is kept only when it lowers the count of crossing pairs, so the result
/// never has more pairs than the input. Stops when no pair is left or no move helps, after at most
/// `max_tries` moves.
CrossingRepair repair_self_crossings(std::span<Vec3> x, IntersectionCounter& counter,
                                     const Topology& cloth, std::span<const std::uint8_t> fixed,
                                     double margin, int max_tries = 200);

}  // namespace clothcd::sim
