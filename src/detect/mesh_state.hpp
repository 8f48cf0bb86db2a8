#pragma once
// One mesh as a detector holds it between calls: topology, tree, the positions of the current
// step, the step's feature boxes and the active restriction. SelfDetector holds one, PairDetector
// two; the stages read it, and only these methods change the tree or the restriction.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/mesh/topology.hpp"
#include "detect/feature_boxes.hpp"
#include "detect/positions.hpp"
#include "detect/step_positions.hpp"

namespace clothcd::detail {

/// Which feature pairs a pass tests: all of them, those the active restriction keeps (a VF pair
/// with an active vertex or face, an EE pair with an active edge), or the others.
enum class Scope : std::uint8_t { All, Active, Inactive };

struct MeshState {
  Topology topo;
  Bvh bvh;
  // The positions of the current call, and which vertices changed since the call before: one
  // copy and one comparison a call, shared by the refit and the feature boxes.
  StepPositions step;
  const std::vector<Eigen::Vector3d>& v0 = step.x0();
  const std::vector<Eigen::Vector3d>& v1 = step.x1();
  std::uint64_t bvh_call = 0;  // the call of `step` the tree was last swept at (0: none)
  // Swept boxes of the features, updated where vertices moved (see FeatureBoxes).
  FeatureBoxes boxes;
  // The active restriction (set_active_*): active vertices, edges and faces, and the nodes
  // holding a face that can represent an in-scope pair.
  bool restricted = false;
  std::vector<std::uint8_t> vertex_active, edge_active, face_active, node_active;

  /// `cones`: a tree with normal cones and contours (self culling); otherwise boxes only.
  /// `face_blocks`: feature boxes gathered per face (BoxStore::Blocks); otherwise in separate
  /// arrays. `what` names the
  /// reference shape in errors.
  MeshState(std::vector<Face> faces, int nv, PointsIn reference, std::string_view what,
            BvhBuild build, bool cones, bool face_blocks);
  MeshState(const MeshState&) = delete;  // v0 and v1 refer into `step`
  MeshState& operator=(const MeshState&) = delete;

  /// The scope of a pass that honours the restriction.
  [[nodiscard]] Scope scope() const { return restricted ? Scope::Active : Scope::All; }
  /// The node flags a restricted traversal descends through (empty: every node).
  [[nodiscard]] std::span<const std::uint8_t> active_nodes() const {
    return restricted ? std::span<const std::uint8_t>(node_active)
                      : std::span<const std::uint8_t>();
  }

  /// The swept boxes (and cones, when `options` asks) of the current step, redone where vertices
  /// moved since the tree's last sweep.
  void sweep(const RefitOptions& options) {
    bvh.refit_moved(v0, v1, options, step.changed_since(bvh_call));
    bvh_call = step.call();
  }
  /// The tree's boxes at the static positions of a proximity query, widened by h; the next
  /// sweep redoes every node.
  void refit_static(double h);
  /// Restricts passes to the pairs with an active vertex (see Scope); `mesh` names the mesh in
  /// errors ("" for a single mesh).
  void set_active_vertices(std::span<const int> vertices, std::string_view mesh);
  /// Restricts passes to the pairs with a vertex, edge or face of an active face.
  void set_active_faces(std::span<const int> faces);
  void clear_active() { restricted = false; }
  /// A new tree over `reference`; the restriction goes with the old one.
  void rebuild(PointsIn reference, std::string_view what, BvhBuild build, bool cones);
};

}  // namespace clothcd::detail
