#pragma once
/// @file
/// The collision stage (docs/simulator.md 3): per
/// substep, proximity repulsion and friction within the cloth thickness, then CCD passes whose
/// hits accumulate as linearized constraints that projected Gauss-Seidel satisfies together
/// (inelastic projection, Harmon et al. 2008; the impulses are those of Bridson, Fedkiw,
/// Anderson 2002), then rigid impact zones (Provot 1997) as the fail-safe. Cloth self contact
/// goes through clothcd::SelfDetector (sound culling only), cloth-body contact through clothcd
/// BVHs of both meshes and the conservative CCD kernels. Body vertices have infinite mass, and so
/// have pinned cloth vertices. Processing is sequential over sorted pairs, so results do not
/// depend on the thread count.

#include <memory>
#include <span>

#include "clothcd/sim/cloth_model.hpp"
#include "clothcd/sim/collision.hpp"

namespace clothcd::sim {

struct ContactOptions {
  bool self = true;             ///< cloth-cloth contact
  bool body = true;             ///< cloth-body contact
  double thickness = 1e-3;      ///< repulsion distance d-hat (m)
  double ccd_thickness = 1e-5;  ///< minimum separation the CCD keeps (m)
  int ccd_iterations = 5;       ///< CCD passes (each followed by the projection) before zones
  int zone_rounds = 30;         ///< impact-zone rounds before giving up
  /// Share of the overlap d-hat - d that repulsion removes per substep.
  double repulsion_fraction = 0.1;
  /// Gauss-Seidel sweeps of the repulsion impulses (the first one also applies friction). On
  /// multilayer-kick frames 1-3, 20 instead of 1 left 31,521 instead of 154,054 CCD hits.
  int repulsion_sweeps = 20;
  /// Repulsion keeps each cloth vertex of a contact (weight >= 0.05) from approaching the other
  /// side, then tops up the contact as a whole; false: the contact's single impulse spread by
  /// weight, which threw light vertices off resting contacts (docs/simulator.md 3.1).
  bool pointwise_repulsion = true;
  /// Cloth vertices within `thickness` of a body face at the substep start are held to the
  /// body's normal velocity (plus the repulsion target) inside the dynamics solve, and let go
  /// when that would hold them down (docs/simulator.md 3.1); false: only the response after the
  /// solve stops them.
  bool body_constraints = true;
  /// The other contacts within `thickness` at the substep start (cloth-cloth, and body vertices
  /// or edges against the cloth) become couplings of the dynamics solve: a stiff penalty keeps
  /// each pair from approaching faster than the repulsion target, let go when it would hold the
  /// pair together (docs/simulator.md 3.1); false: only repulsion after the solve separates them.
  bool coupled_contacts = true;
  /// Every CCD pass and zone round tests every pair (diagnostic). By default, passes after the
  /// first test only pairs with a vertex whose velocity the last response changed or that was in
  /// the last pass's hits: every other pair keeps a motion already tested without a hit, so
  /// both give bitwise the same result (tested).
  bool full_passes = false;
  /// Cloth vertices found inside the body (behind a body face that one of their faces crosses)
  /// move out along that face's normal by up to this much per substep (m; 0: off, the default).
  /// 2 mm from frame 0 undid the body crossings of dress-kick and of multilayer-kick's frames
  /// 51-53, but resumed inside multilayer-kick's deep tangle of frame 72 it gave 803 and 813
  /// crossings where the run without it had 619.
  double untangle_step = 0.0;
  /// Impact zones touching the body or a pin follow the affine motion nearest their anchors'
  /// velocities where the anchors determine one (not flat, strain |h A| under 0.2), else the
  /// rigid one; false: always the rigid one. Free zones are rigid either way.
  bool affine_zones = true;
  double friction = 0.2;  ///< Coulomb coefficient of the contact impulses
  /// Smallest weight at which a contact's cloth vertex gets its own repulsion point by point
  /// (`pointwise_repulsion`); lighter ones are left to the contact's own top-up impulse.
  double pointwise_weight = 0.05;
  /// How closely the CCD kernels refine a hit's time of impact (fraction of the substep, on the
  /// early side). The response uses the geometry at toi only for its normal and weights; on
  /// dress-rumba frame 1, 1e-4 took 5.5 s and 0.05 took 3.6 s per frame.
  double toi_tolerance = 0.05;
  /// Bisections of the CCD distance filter before a kernel runs (DetectOptions::
  /// distance_filter_depth): each level costs at most 2^level distance evaluations, far less
  /// than a kernel; on multilayer-kick frame 2 a restricted pass ran about 16,000 kernels with
  /// the whole-step bound alone and about 500 with 6 levels.
  int distance_filter_depth = 6;
  /// Projected Gauss-Seidel sweeps per CCD pass at most (the inelastic projection) ...
  int projection_sweeps = 100;
  /// ... stopping once no sweep changes a velocity by more than this many CCD separations
  /// (`ccd_thickness`) per substep.
  double projection_tolerance = 0.01;
  /// Impact-zone rounds that still demand the CCD separation (at most half of `zone_rounds`);
  /// later rounds demand only no contact, so a zone that keeps every pair apart but cannot
  /// restore the margin (cloth held between two body points that move differently) is accepted.
  int margin_rounds = 5;
};

class ContactHandler final : public CollisionHandler {
 public:
  /// `model` must outlive the handler; its stitches mark pairs that never collide.
  ContactHandler(const ClothModel& model, const ContactOptions& options);
  ~ContactHandler() override;

  void prepare(const SubstepContext& ctx) override;
  void contact_constraints(std::vector<ContactConstraint>& out) const override;
  void contact_couplings(std::vector<ContactCoupling>& out) const override;
  CollisionStats respond(const SubstepContext& ctx, std::span<Vec3> v_star) override;

  [[nodiscard]] const ContactOptions& options() const { return options_; }

 private:
  struct Impl;
  ContactOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothcd::sim
