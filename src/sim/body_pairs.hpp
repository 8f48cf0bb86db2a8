#pragma once
// Cloth-body feature pairs whose boxes come within a gap of each other, from the leaf pairs of
// both meshes' BVHs: (cloth vertex, body face), (body vertex, cloth face), (cloth edge, body
// edge). Each feature has one designated incident face and a pair is taken only from the leaf
// pair of its features' designated faces, so it comes once: no duplicates to sort away (the sort
// of the duplicated lists took 37% of the cloth-body queries on multilayer-rumba frame 61).

#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/mesh/topology.hpp"
#include "clothcd/sim/elements.hpp"

namespace clothcd::sim::detail {

/// Axis-aligned boxes, one per feature, as corner lists.
struct BoxList {
  std::vector<Vec3> lo, hi;
};

/// The boxes of a mesh's vertices, edges and faces.
struct MeshBoxes {
  BoxList vertex, edge, face;
};

/// Fills `out` with the boxes of the features of `topo` spanned by positions a and b (a == b:
/// static boxes), for the features whose use flag is set (empty: all); the others keep what they
/// held.
void fill_feature_boxes(const Topology& topo, std::span<const Vec3> a, std::span<const Vec3> b,
                        std::span<const std::uint8_t> vertex_use,
                        std::span<const std::uint8_t> edge_use,
                        std::span<const std::uint8_t> face_use, MeshBoxes& out);

/// One mesh of the query. Boxes are read only for the features used (and, for faces, those
/// below the flagged nodes); `*_use` empty means all.
struct PairSide {
  const Topology* topo = nullptr;
  const Bvh* bvh = nullptr;
  const MeshBoxes* boxes = nullptr;
  std::span<const int> vertex_face, edge_face;  ///< designated faces (designated_faces())
  std::span<const std::uint8_t> vertex_use, edge_use;
  /// Faces that may pair with the other mesh's vertices (the cloth's: not escaping ones).
  std::span<const std::uint8_t> face_use;
};

struct BodyPairs {
  std::vector<std::pair<int, int>> vf_cb;  ///< (cloth vertex, body face)
  std::vector<std::pair<int, int>> vf_bc;  ///< (body vertex, cloth face)
  std::vector<std::pair<int, int>> ee;     ///< (cloth edge, body edge)
};

/// The smallest incident face of every vertex and every edge (-1 for none).
void designated_faces(const Topology& topo, std::vector<int>& vertex_face,
                      std::vector<int>& edge_face);

/// Face pairs (cloth face, body face) whose features a caller's bound leaves out at once (see
/// close_feature_pairs); empty: none.
using FacePairSkip = std::function<bool(int cloth_face, int body_face)>;

/// The feature pairs whose boxes are within `gap` on every axis (lo_a <= hi_b + gap and
/// lo_b <= hi_a + gap), sorted, each once. The BVHs' leaf boxes must contain their faces'
/// feature boxes grown by gap / 2 (a refit with thickness `gap` of the same positions does).
/// `cloth_nodes` (one flag per cloth BVH node, empty: all) restricts the cloth side to the
/// leaves below flagged nodes; they must hold every designated face of a used cloth feature.
/// `skip(f, g)` true leaves out every pair whose features' designated faces are f and g. The
/// same lists for any thread count.
[[nodiscard]] BodyPairs close_feature_pairs(const PairSide& cloth, const PairSide& body, double gap,
                                            std::span<const std::uint8_t> cloth_nodes = {},
                                            const FacePairSkip& skip = {});

}  // namespace clothcd::sim::detail
