#pragma once
/// @file
/// The cloth's rest state and material: lumped masses, membrane triangles (with the sliver rule),
/// bending hinges and stitches (docs/simulator.md section 1). Built once; positions live in
/// ClothState.

#include <array>
#include <utility>
#include <vector>

#include "clothcd/mesh/topology.hpp"
#include "clothcd/sim/elements.hpp"

namespace clothcd::sim {

/// Physical parameters; defaults as in docs/simulator.md 1.5.
struct ClothMaterial {
  double area_density = 0.15;         ///< rho_A, kg/m^2
  double stretch_stiffness = 260.0;   ///< E*t, N/m
  double poisson = 0.25;              ///< nu
  double bending_stiffness = 1e-7;    ///< k_b, N*m
  double damping = 1e-3;              ///< Rayleigh stiffness damping beta, s
  double friction = 0.2;              ///< mu (used by the collision stage)
  double stitch_stiffness = 1000.0;   ///< k_st, N/m
  double cot_clamp = 10.0;            ///< |cot| bound of the bending weights on slivers
  double sliver_area_ratio = 1e-3;    ///< membrane skipped below this fraction of the median area
  double sliver_min_angle_deg = 5.0;  ///< ... or below this minimum angle
  /// Largest principal stretch the limiter allows (cotton's 1.06); 0: no stretch limit.
  double strain_limit = 1.06;
  /// Smallest principal stretch the limiter allows; 0: no compression limit.
  double compression_limit = 0.0;
};

/// Vertex a tied to (1 - r) x_b + r x_c (stage.obj's `stitch a b c r`, 0-based).
struct Stitch {
  int a = 0, b = 0, c = 0;
  double r = 0.0;
};

/// What a cloth is made from. `pattern` (one 2D point per vertex, metres) is the flat rest shape
/// when present; otherwise the initial positions are the rest shape.
struct ClothMeshInput {
  std::vector<Vec3> positions;
  std::vector<Face> faces;
  std::vector<Vec2> pattern;
  std::vector<Stitch> stitches;
};

/// A hinge: x0-x1 the shared edge, x2 and x3 the opposite vertices, with Bergou weights.
struct Hinge {
  std::array<int, 4> v{};
  HingeWeights w;
};

/// Stitch as a constant quadratic: up to 3 distinct vertices with weights w, energy
/// k/2 |sum w_m x_m|^2.
struct StitchTerm {
  std::array<int, 3> v{};
  std::array<double, 3> w{};
  int count = 0;
};

class ClothModel {
 public:
  /// Throws clothcd::InputError for bad faces, stitch indices or a pattern of the wrong size.
  ClothModel(const ClothMeshInput& input, const ClothMaterial& material);

  [[nodiscard]] int num_vertices() const { return topology_.num_vertices(); }
  [[nodiscard]] const Topology& topology() const { return topology_; }
  [[nodiscard]] const ClothMaterial& material() const { return material_; }
  [[nodiscard]] const MembraneModuli& moduli() const { return moduli_; }
  [[nodiscard]] const std::vector<double>& mass() const { return mass_; }
  [[nodiscard]] const std::vector<MembraneRest>& membrane_rest() const { return rest_; }
  /// False for slivers: they keep their mass and collide but have no membrane term.
  [[nodiscard]] const std::vector<bool>& membrane_active() const { return active_; }
  [[nodiscard]] int num_slivers() const { return num_slivers_; }
  [[nodiscard]] const std::vector<Hinge>& hinges() const { return hinges_; }
  [[nodiscard]] const std::vector<StitchTerm>& stitches() const { return stitches_; }
  /// Vertex pairs (u < w, sorted) that collisions and intersection counts treat as one point:
  /// the vertices of each stitch term, and vertices joined by a chain of stitches that lie
  /// within one mean edge length of each other in the initial shape. A seam sews panels by
  /// vertex-to-edge stitches whose allowances overlap, so faces a few millimetres apart across
  /// a seam touch or cross by construction; a welded mesh would make them neighbours. The distance
  /// bound keeps the two ends of a long seam (one chain) apart.
  [[nodiscard]] const std::vector<std::pair<int, int>>& seam_links() const { return seam_links_; }
  [[nodiscard]] const std::vector<Vec3>& initial_positions() const { return initial_; }

 private:
  void link_seams();

  Topology topology_;
  ClothMaterial material_;
  MembraneModuli moduli_;
  std::vector<double> mass_;
  std::vector<MembraneRest> rest_;
  std::vector<bool> active_;
  int num_slivers_ = 0;
  std::vector<Hinge> hinges_;
  std::vector<StitchTerm> stitches_;
  std::vector<std::pair<int, int>> seam_links_;
  std::vector<Vec3> initial_;
};

}  // namespace clothcd::sim
