#pragma once
/// @file
/// A scene in motion: frame by frame, with adaptive substeps from the body's motion
/// (n = clamp(ceil(displacement / 4 cm), 4, 32); docs/simulator.md 4).

#include <memory>

#include "clothcd/sim/contact_handler.hpp"
#include "clothcd/sim/intersections.hpp"
#include "clothcd/sim/scene.hpp"

namespace clothcd::sim {

/// Figures of one frame, as written to the manifest.
struct FrameStats {
  int frame = 0;  ///< the frame reached (1 = first simulated frame)
  double time = 0.0;
  int substeps = 0;
  int solves = 0;
  long long pcg_iterations = 0;
  int max_pcg_iterations = 0;
  int halvings = 0;
  bool pcg_converged = true;
  /// The PCG tolerance of the frame's solves: SolverOptions::fast_pcg_tolerance in a fast frame
  /// (more substeps than SubstepRule::min), pcg_tolerance otherwise.
  double pcg_tolerance = 0.0;
  double seconds = 0.0;
  double max_stretch = 0.0;       ///< at the end of the frame (membrane triangles)
  StrainFigures strain;           ///< every triangle at the end of the frame
  StrainLimitStats strain_limit;  ///< the limiter over the frame's substeps
  double strain_seconds = 0.0;    ///< the limiter's wall time
  double body_displacement = 0.0;
  bool finite = true;
  /// The collision stage, summed over the frame's substeps (zero without collisions); its
  /// `seconds` is the manifest's collision_seconds, its `unresolved` the hits left when the zone
  /// rounds ran out in the substeps' last halving.
  CollisionStats collision;
  /// The self detector's full CCD passes and proximity queries of the frame (see
  /// SelfCcdFigures: counts depend on the run's history, so a resumed run's may differ).
  SelfCcdFigures self_ccd;
  SelfProximityFigures self_proximity;
  /// Where collision.seconds went (see CollisionPartTimes).
  CollisionPartTimes collision_parts;
  /// Intersecting triangle pairs at the frame's end (-1: not counted).
  long long self_intersections = -1;
  long long body_intersections = -1;
  double intersection_seconds = 0.0;
};

/// Intersecting triangle pairs of one state.
struct IntersectionCount {
  long long self = 0;
  long long body = 0;
};

class Simulation {
 public:
  /// Takes the scene's body and pins. Throws InputError on inconsistent pins.
  explicit Simulation(Scene scene);
  ~Simulation();

  [[nodiscard]] const Scene& scene() const { return scene_; }
  [[nodiscard]] const ClothModel& model() const { return *model_; }
  [[nodiscard]] ClothSolver& solver() { return *solver_; }
  [[nodiscard]] ClothState& state() { return state_; }
  [[nodiscard]] int frame() const { return frame_; }
  /// Replaces the state (resume); `frame` is the frame it belongs to.
  void set_state(ClothState state, int frame);

  FrameStats advance_frame();

  /// What the constructor's repair of the starting shape did (Scene::repair_initial_crossings).
  [[nodiscard]] const CrossingRepair& initial_repair() const { return initial_repair_; }

  /// Intersecting triangle pairs (cloth-cloth, cloth-body) at the current state and time.
  [[nodiscard]] IntersectionCount count_intersections();
  /// The body's vertices at the current time (empty without a body).
  [[nodiscard]] std::vector<Vec3> body_positions();

 private:
  std::unique_ptr<ContactHandler> contact_;
  std::unique_ptr<IntersectionCounter> counter_;
  Scene scene_;
  std::unique_ptr<ClothModel> model_;
  std::unique_ptr<ClothSolver> solver_;
  ClothState state_;
  CrossingRepair initial_repair_;
  int frame_ = 0;
};

}  // namespace clothcd::sim
