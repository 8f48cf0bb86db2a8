#pragma once
/// @file
/// Implicit Euler with one Newton step solved by filtered block-Jacobi PCG (Baraff & Witkin 1998;
/// docs/simulator.md 2.1): (M + h(h+beta)H) dv = h(f_ext - grad U(x_n) - (h+beta) H v_n),
/// v* = v_n + dv, x_{n+1} = x_n + h v*. Results are bitwise identical for any thread count.

#include <cstdint>
#include <memory>
#include <vector>

#include "clothcd/sim/cloth_model.hpp"
#include "clothcd/sim/collision.hpp"
#include "clothcd/sim/strain.hpp"

namespace clothcd::sim {

/// Positions, velocities, the last velocity change (PCG warm start) and the time: everything a
/// run needs to continue bitwise identically.
struct ClothState {
  std::vector<Vec3> x;
  std::vector<Vec3> v;
  std::vector<Vec3> dv;
  double time = 0.0;
};

/// Vertices held by a rigid handle: target(t) = center + v t + R(axis, omega t)(x0 - center),
/// x0 being the vertices' positions when the group was added.
struct PinGroup {
  std::vector<int> vertices;
  Vec3 center = Vec3::Zero();
  Vec3 axis = Vec3::UnitY();
  double angular_velocity = 0.0;  ///< rad/s about `axis`
  Vec3 velocity = Vec3::Zero();   ///< m/s
};

struct SolverOptions {
  Vec3 gravity{0.0, -9.81, 0.0};
  int pcg_max_iterations = 200;
  double pcg_tolerance = 1e-3;
  /// With contact constraints or couplings in the solve, the first solve stops at this relative
  /// residual (or pcg_tolerance, if larger): it only decides which of them to let go, and the
  /// solve redone after that reaches pcg_tolerance: a complete first solve is mostly wasted when
  /// a redo follows anyway (docs/simulator.md 2.1). At or below pcg_tolerance: the complete
  /// first solve, redone only when something was let go.
  double release_tolerance = 1e-2;
  /// The PCG tolerance of the substeps of a fast frame (ClothSolver::step's `fast`): one that
  /// the substep rule gave more than its minimum of substeps, so that each substep moves the body
  /// or the cloth as far as the rule allows and the time step's own error outweighs the solve's
  /// (docs/simulator.md 2.1). 0: pcg_tolerance in every frame.
  double fast_pcg_tolerance = 0.0;
  /// Vertices per aggregate of the PCG's coarse correction (a two-level preconditioner: block
  /// Jacobi plus one translation per aggregate, factored every substep); 0: block Jacobi alone.
  int coarse_aggregate = 0;
  /// A substep is halved (up to `max_halvings` times) when PCG ends above this relative residual
  /// or the result is not finite.
  double halve_residual = 1e-2;
  int max_halvings = 3;
  /// Also halve a substep whose collision response leaves CCD hits unresolved (the impact
  /// zones gave up): a shorter substep asks of each zone a motion closer to its anchors'.
  bool halve_unresolved = true;
  /// Strain limiter (ClothMaterial::strain_limit): Gauss-Seidel sweeps at most on the solve's
  /// result and again before the collision stage's first CCD pass (after repulsion and
  /// friction); after how many of a substep's first CCD passes' projections it runs again,
  /// holding the vertices the projection changed; its sweeps there at most (each call continues
  /// where the last stopped). Later passes run without it, so that CCD settles the motion.
  int strain_sweeps = 40;
  int strain_ccd_passes = 2;
  int strain_ccd_sweeps = 4;
};

struct StepStats {
  int solves = 0;          ///< PCG solves (more than one when halved)
  int pcg_iterations = 0;  ///< summed over solves
  int max_pcg_iterations = 0;
  int halvings = 0;
  bool converged = true;       ///< every solve reached its tolerance
  double pcg_tolerance = 0.0;  ///< the tolerance the solves aimed at
  double max_stretch = 0.0;    ///< largest membrane stretch at the substeps' start states
  StrainLimitStats strain;     ///< the limiter's passes, summed (residual: the largest)
  double strain_seconds = 0.0;
  CollisionStats collision;
};

/// Provides the body's vertices at a time (empty when there is no body).
class BodyPositions {
 public:
  virtual ~BodyPositions() = default;
  virtual void positions_at(double t, std::vector<Vec3>& out) = 0;
  [[nodiscard]] virtual const std::vector<Face>& faces() const = 0;
};

class ClothSolver {
 public:
  ClothSolver(const ClothModel& model, const SolverOptions& options);
  ~ClothSolver();
  ClothSolver(const ClothSolver&) = delete;
  ClothSolver& operator=(const ClothSolver&) = delete;

  /// Adds a handle; its rest offsets are taken from `x`. Throws InputError on a bad vertex id.
  void add_pins(const PinGroup& group, const std::vector<Vec3>& x);
  /// Optional; not owned. Null disables collision handling.
  void set_collision_handler(CollisionHandler* handler) { handler_ = handler; }
  void set_body(BodyPositions* body) { body_ = body; }

  /// The state at rest: initial positions, zero velocity, t = 0.
  [[nodiscard]] ClothState initial_state() const;
  /// Advances `state` by h (halving on failure as SolverOptions says). `fast`: a substep of a
  /// fast frame, solved to SolverOptions::fast_pcg_tolerance when that is set.
  StepStats step(ClothState& state, double h, bool fast = false);

  /// Potential energy (elastic + gravity) at x.
  [[nodiscard]] double potential_energy(const std::vector<Vec3>& x) const;
  /// Kinetic energy of v.
  [[nodiscard]] double kinetic_energy(const std::vector<Vec3>& v) const;
  /// Largest membrane stretch (sigma_max(F) - 1) at x.
  [[nodiscard]] double max_stretch(const std::vector<Vec3>& x) const;
  /// One flag per vertex: held by a body contact constraint in the last substep.
  [[nodiscard]] const std::vector<std::uint8_t>& body_contact() const;

  [[nodiscard]] const ClothModel& model() const { return model_; }

 private:
  struct Impl;
  bool try_step(ClothState& state, double h, double tolerance, StepStats& stats, bool allow_fail);
  void substep(ClothState& state, double h, double tolerance, int depth, StepStats& stats);

  const ClothModel& model_;
  SolverOptions options_;
  std::unique_ptr<Impl> impl_;
  CollisionHandler* handler_ = nullptr;
  BodyPositions* body_ = nullptr;
};

}  // namespace clothcd::sim
