#pragma once
/// @file
/// The collision stage (docs/simulator.md 3): per
/// substep, proximity repulsion and friction within the cloth thickness, then CCD passes whose
/// hits accumulate as linearized constraints that projected Gauss-Seidel satisfies together
/// (inelastic projection, Harmon et al. 2008; the impulses are those of Bridson, Fedkiw,
/// Anderson 2002), then rigid impact zones (Provot 1997) as the fail-safe. Cloth self contact
/// goes through clothcd::SelfDetector (no culling, or the sound culling), cloth-body contact
/// through clothcd BVHs of both meshes and the conservative CCD kernels. Body vertices have
/// infinite mass, and so have pinned cloth vertices. Processing is sequential over sorted pairs, so
/// results do not depend on the thread count.

#include <functional>
#include <memory>
#include <span>

#include "clothcd/detect/types.hpp"
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
  /// Gauss-Seidel sweeps of the repulsion impulses (the first one also applies friction). More
  /// sweeps leave the CCD passes far fewer hits to settle.
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
  /// Off by default: it undoes shallow body crossings, but inside a deep tangle it can add
  /// crossings.
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
  /// early side). The response uses the geometry at toi only for its normal and weights, so a
  /// coarse tolerance saves kernel time without changing what the response needs.
  double toi_tolerance = 0.05;
  /// Bisections of the CCD distance filter before a kernel runs (DetectOptions::
  /// distance_filter_depth): each level costs at most 2^level distance evaluations, far less
  /// than a kernel, and on resting layers each level spares many kernels.
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
  /// Node culling of the self CCD: Culling::Sound (the default) or Culling::None; the unsound
  /// cone rules are refused by the scene parser. Both find the same pairs, so the motion is
  /// bitwise the same (tested); only the time and the figures of SelfCcdFigures differ
  /// (docs/results/in_situ.md compares them on the garment scenes): most of the triangle pair
  /// tests left are between layers or folds that really are close, which no normal cone can
  /// clear.
  Culling culling = Culling::Sound;
  /// The normal cones the sound culling uses (no effect without culling): Provot, Proposed or
  /// Exact. Again only the time and the figures change, never the motion.
  ConePolicy cone_policy = ConePolicy::Proposed;
  /// The sound culling tests cones only on tree nodes of at least this many triangles
  /// (DetectOptions::cull_min_triangles): a smaller node can save few pair tests and costs about
  /// as much to test. Any value gives the same motion; 0 tests every node.
  int cull_min_triangles = 16;
  /// The self and cloth-body CCD detectors start each full pass's traversal from the previous
  /// one's front of node pairs (DetectOptions::reuse_front). The same pairs, so the same motion;
  /// only the traversal's cost changes (docs/results/front.md).
  bool reuse_front = false;
  /// A measurement hook, empty by default: when set, called with the cloth's positions at the
  /// start and the end of the step every full self CCD pass detects (the passes SelfCcdFigures
  /// counts), before the pass. It sees the motion and changes nothing (`clothcd experiment
  /// --in-situ` counts there what other culling rules would test).
  std::function<void(std::span<const Vec3> x0, std::span<const Vec3> x1)> on_full_self_pass;
};

/// What the self detector's full CCD passes cost, summed over calls: the passes that test every
/// pair (the first of a substep, and any unrestricted later one), not the restricted passes that
/// test only pairs with a vertex the response moved. Counts follow from the motion and the
/// detector's history (its tree, built on the first substep it saw): they do not depend on the
/// thread count, but a run resumed from a saved state has a fresh detector and so other counts.
struct SelfCcdFigures {
  long long calls = 0;
  long long triangle_pairs = 0;  ///< DetectStats::triangle_pairs
  long long nodes_culled = 0;    ///< DetectStats::nodes_culled
  double refit_s = 0.0;          ///< DetectStats::time_refit (boxes and cones)
  double traversal_s = 0.0;      ///< DetectStats::time_traverse
  double narrow_s = 0.0;         ///< DetectStats::time_narrow
  SelfCcdFigures& operator+=(const SelfCcdFigures& o);
};

/// What the self proximity queries (at the repulsion distance, one per substep) cost, summed
/// over calls. The detector reports no traversal figures for them, so these are what the
/// contact stage sees: the pairs taken over from the last CCD pass and the pairs found.
struct SelfProximityFigures {
  long long calls = 0;
  long long reused_pairs = 0;  ///< ProximityResult::reused_pairs
  long long pairs = 0;         ///< VF and EE pairs found within the thickness
  double query_s = 0.0;        ///< wall time of the queries
  SelfProximityFigures& operator+=(const SelfProximityFigures& o);
};

/// Where the collision stage's wall time goes, summed over substeps (seconds). The parts do not
/// overlap and together make up nearly all of CollisionStats::seconds; what they leave out is
/// bookkeeping between them. They measure, they change nothing.
struct CollisionPartTimes {
  double setup_s = 0.0;      ///< contact geometry, both detectors' start (creation, self rebuild)
  double crossings_s = 0.0;  ///< crossing pairs at the substep start (and escapes), its end's check
  double proximity_s = 0.0;  ///< proximity queries (self, body) and the contacts built from them
  double response_s = 0.0;   ///< repulsion, friction, escapes and the inelastic projections
  double ccd_self_s = 0.0;   ///< the self detector's calls (and active sets) in CCD passes, zones
  double ccd_body_s = 0.0;   ///< the cloth-body detector's calls there
  double ccd_hits_s = 0.0;   ///< turning the detectors' hits into contacts (retests, separation)
  double zones_s = 0.0;      ///< impact zones, less their detector calls and hits
  [[nodiscard]] double total() const {
    return setup_s + crossings_s + proximity_s + response_s + ccd_self_s + ccd_body_s + ccd_hits_s +
           zones_s;
  }
  CollisionPartTimes& operator+=(const CollisionPartTimes& o);
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
  /// The self detector's figures since the last call (zero without self contact); resets them.
  SelfCcdFigures take_self_ccd_figures();
  SelfProximityFigures take_self_proximity_figures();
  /// The collision stage's part times since the last call; resets them.
  CollisionPartTimes take_part_times();

 private:
  struct Impl;
  ContactOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothcd::sim
