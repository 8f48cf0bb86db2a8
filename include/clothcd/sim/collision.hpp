#pragma once
/// @file
/// The plug-in point of the collision stage (docs/simulator.md section 3). The integrator calls
/// one handler per substep in two phases: `prepare` at the start state (proximity query at x_n and
/// b_n), then `respond` on the candidate velocities v* (repulsion, friction, CCD impulses, impact
/// zones). The handler changes v* only; positions follow as x_{n+1} = x_n + h v*.

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "clothcd/mesh/topology.hpp"
#include "clothcd/sim/elements.hpp"

namespace clothcd::sim {

/// What a handler sees of one substep from t0 to t0 + h.
struct SubstepContext {
  double t0 = 0.0;
  double h = 0.0;
  std::span<const Vec3> x0;              ///< cloth at t0 (intersection-free by invariant)
  std::span<const double> inverse_mass;  ///< 0 for pinned cloth vertices
  const Topology* cloth = nullptr;
  std::span<const Vec3> body_t0;  ///< body vertices at t0 and t0 + h (empty: no body)
  std::span<const Vec3> body_t1;
  const std::vector<Face>* body_faces = nullptr;
  /// Optional: called once before the first CCD pass (after repulsion and friction, no vertex
  /// flagged) and after each CCD pass's projection, with v and one flag per cloth vertex (set:
  /// the projection changed its velocity); it may change v (the strain limiter does) and must
  /// flag every vertex it changes, so the next pass tests them.
  std::function<void(std::span<Vec3>, std::span<std::uint8_t>)> after_projection;
};

/// Per-substep figures a handler reports; summed over a step's substeps and a frame's steps.
struct CollisionStats {
  long long proximity_pairs = 0;
  long long ccd_hits = 0;
  int ccd_passes = 0;
  int zones = 0;  ///< impact zones of a substep's last round; summed over substeps
  int largest_zone = 0;
  int zone_rounds = 0;
  long long unresolved = 0;  ///< CCD hits still present when the zone rounds ran out
  long long excluded = 0;    ///< CCD hits left out: their triangles already crossed at t0
  double seconds = 0.0;      ///< wall time of the stage (the integrator measures it)
  /// Sums every figure but largest_zone, which becomes the larger of the two.
  CollisionStats& operator+=(const CollisionStats& o) {
    proximity_pairs += o.proximity_pairs;
    ccd_hits += o.ccd_hits;
    ccd_passes += o.ccd_passes;
    zones += o.zones;
    largest_zone = std::max(largest_zone, o.largest_zone);
    zone_rounds += o.zone_rounds;
    unresolved += o.unresolved;
    excluded += o.excluded;
    seconds += o.seconds;
    return *this;
  }
};

/// A cloth vertex resting on the body at the substep start: the dynamics solve moves it along
/// `n` (unit, away from the body) at exactly `normal_velocity`, so the cloth it holds up is
/// held up within the same solve (Baraff & Witkin 1998), instead of falling on while only the
/// vertex in contact is stopped afterwards.
struct ContactConstraint {
  int vertex = -1;
  Vec3 n = Vec3::Zero();
  double normal_velocity = 0.0;
};

/// Two cloth surfaces (or a cloth face and a body vertex or edge) within the thickness at the
/// substep start: the dynamics solve keeps their relative normal velocity
/// n . sum_k c_k v_k + `body_velocity` from falling below `normal_velocity` through a stiff
/// penalty on it (a contact damper), and lets it go when it would hold the pair together. Why:
/// repulsion after the solve moved a layer pushed by another layer alone, at up to 2.9 m/s per
/// substep, while the cloth around it stayed behind (docs/simulator.md 3.1).
struct ContactCoupling {
  std::array<int, 4> vertex{-1, -1, -1, -1};  ///< cloth vertices; -1: none (a body point)
  std::array<double, 4> c{};                  ///< barycentric weights, one side negative
  Vec3 n = Vec3::Zero();                      ///< unit, from the negative side to the positive
  double body_velocity = 0.0;                 ///< the body points' share of the relative velocity
  double normal_velocity = 0.0;
};

class CollisionHandler {
 public:
  virtual ~CollisionHandler() = default;
  /// Before the dynamics solve.
  virtual void prepare(const SubstepContext& ctx) = 0;
  /// After prepare: the constraints the dynamics solve should keep (default: none).
  virtual void contact_constraints(std::vector<ContactConstraint>& out) const { out.clear(); }
  /// After prepare: the couplings the dynamics solve should keep (default: none).
  virtual void contact_couplings(std::vector<ContactCoupling>& out) const { out.clear(); }
  /// After it: adjust v* in place.
  virtual CollisionStats respond(const SubstepContext& ctx, std::span<Vec3> v_star) = 0;
};

}  // namespace clothcd::sim
