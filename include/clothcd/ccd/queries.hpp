#pragma once
/// @file
/// Elementary continuous collision queries over one linear motion t in [0, 1]: a vertex against a
/// face (VF) and an edge against an edge (EE). Names follow ipc-toolkit: _t0/_t1 are the start and
/// end of the step.

#include <Eigen/Core>

namespace clothcd {

struct VertexFaceQuery {
  Eigen::Vector3d v_t0, f0_t0, f1_t0, f2_t0;
  Eigen::Vector3d v_t1, f0_t1, f1_t1, f2_t1;
};

struct EdgeEdgeQuery {
  Eigen::Vector3d ea0_t0, ea1_t0, eb0_t0, eb1_t0;
  Eigen::Vector3d ea0_t1, ea1_t1, eb0_t1, eb1_t1;
};

struct CcdOptions {
  /// Contact when the distance drops to this (>= 0). 0 is exact contact.
  double thickness = 0.0;
  /// Use the cubic fast path (Bernstein coplanarity cubic + NP filter) where it is well
  /// conditioned; false runs the conservative inclusion solver alone.
  bool fast_path = true;
};

struct CcdResult {
  bool hit = false;
  /// Conservative time of impact in [0, 1]: never later than the true first contact (1 when no hit).
  double toi = 1.0;
};

/// Zero false negatives: every query whose features come within `thickness` during the motion
/// reports a hit. NaN or infinite coordinates throw std::invalid_argument.
[[nodiscard]] CcdResult vertex_face_ccd(const VertexFaceQuery& q, const CcdOptions& opt = {});
[[nodiscard]] CcdResult edge_edge_ccd(const EdgeEdgeQuery& q, const CcdOptions& opt = {});

/// Deforming non-penetration filter (zero thickness only): true when the coplanarity cubic
/// provably has no root in [0, 1], so the pair cannot touch. Sound with a forward error bound.
[[nodiscard]] bool np_filter_culls(const VertexFaceQuery& q);
[[nodiscard]] bool np_filter_culls(const EdgeEdgeQuery& q);

}  // namespace clothcd
