#pragma once
// The contact stage's two detectors: cloth self contact (SelfDetector) and cloth against body
// (PairDetector), both started at a substep's start (created on the first one with the stage's
// options, rebuilt on the start once their trees have loosened: results do not depend on the
// trees, only the time). Every query goes through here, with its restriction as an argument.

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "clothcd/detect/detector.hpp"
#include "clothcd/sim/contact_handler.hpp"
#include "sim/contact/geometry.hpp"

namespace clothcd::sim::detail {

class ContactDetectors {
 public:
  ContactDetectors(const ClothModel& model, const ContactOptions& options)
      : model_(model), opt_(options) {}

  /// At a substep's start: the self detector when `self` and the body detector when `body`
  /// (created, or rebuilt on x0 when loose); `g` learns the body's topology.
  void start(const SubstepContext& ctx, ContactGeometry& g, bool self, bool body);

  // The queries below need their detector started by this substep's start().

  /// Cloth self pairs within `d` at the substep start (unrestricted).
  [[nodiscard]] ProximityResult self_proximity(const ContactGeometry& g, double d);
  /// Cloth self CCD of x0 -> x1; with `active`, only of the pairs with an active vertex.
  [[nodiscard]] DetectResult self_ccd(const ContactGeometry& g, std::span<const Vec3> x1,
                                      const std::vector<int>* active);
  /// Cloth-body pairs within `d` at the substep start (unrestricted); then both trees are
  /// rebuilt on the start when either has loosened past its fit after the last build.
  [[nodiscard]] PairProximityResult body_proximity(const ContactGeometry& g, double d);
  /// Cloth-body CCD of x0 -> x1 against the body's b0 -> b1; with `active` (cloth vertices),
  /// only of the pairs with an active vertex.
  [[nodiscard]] PairDetectResult body_ccd(const ContactGeometry& g, std::span<const Vec3> x1,
                                          const std::vector<int>* active);

 private:
  void start_self(const ContactGeometry& g);
  void start_body(const SubstepContext& ctx, ContactGeometry& g);

  const ClothModel& model_;
  const ContactOptions& opt_;
  std::optional<SelfDetector> self_;
  // The self detector's box area ratio after the first full CCD pass since its tree was built
  // (0: not yet seen). The detector's tree keeps the splits of the shape it was built on; once
  // its boxes have loosened past that (FittedTree::loosened), a substep rebuilds it on its start
  // (the same pairs, faster).
  double self_fit_ = 0.0;
  std::optional<PairDetector> body_;
  std::array<double, 2> body_fit_{0.0, 0.0};  // cloth's and body's tree (0: not yet measured)
};

/// The detector options of the contact stage's CCD: the CCD separation as thickness, the
/// kernels' toi tolerance and the distance filter's depth.
DetectOptions ccd_detect_options(const ContactOptions& o);

}  // namespace clothcd::sim::detail
