#pragma once
// The contact stage's two detectors: cloth self contact (SelfDetector) and cloth against body
// (PairDetector), created on first use with the stage's options and rebuilt on the substep start
// once their trees have loosened (results do not depend on the trees, only the time).

#include <array>
#include <optional>

#include "clothcd/detect/detector.hpp"
#include "clothcd/sim/contact_handler.hpp"
#include "sim/contact/geometry.hpp"

namespace clothcd::sim::detail {

class ContactDetectors {
 public:
  ContactDetectors(const ClothModel& model, const ContactOptions& options)
      : model_(model), opt_(options) {}

  /// The self detector at a substep's start (created, or rebuilt on the start when loose).
  SelfDetector& start_self(const ContactGeometry& g);
  [[nodiscard]] SelfDetector& self() { return *self_; }
  /// After an unrestricted self CCD pass: the first one after a build measures the tree's fit.
  void self_pass_done();

  /// The body detector (created on first use, on the substep's shapes); `g` learns its topology.
  PairDetector& start_body(const SubstepContext& ctx, ContactGeometry& g);
  [[nodiscard]] PairDetector& body() { return *body_; }
  /// After the body proximity query (static boxes at the substep start): both trees rebuilt on
  /// the start when either has loosened past its fit after the last build.
  void body_proximity_done(const ContactGeometry& g);

  /// Figures of the self detector since ContactHandler last took them.
  SelfCcdFigures self_ccd_figures;
  SelfProximityFigures self_proximity_figures;

 private:
  const ClothModel& model_;
  const ContactOptions& opt_;
  std::optional<SelfDetector> self_;
  // The self detector's box area ratio after the first full CCD pass since its tree was built
  // (0: not yet seen). The detector's tree keeps the splits of the shape it was built on; once
  // its boxes have loosened past that (FittedTree::loosened), a substep rebuilds it on its start
  // (the same pairs, faster: multilayer-kick frame 90, the first pass took 96 ms on the frame-0
  // tree, 58 ms rebuilt).
  double self_fit_ = 0.0;
  std::optional<PairDetector> body_;
  std::array<double, 2> body_fit_{0.0, 0.0};  // cloth's and body's tree (0: not yet measured)
};

/// The detector options of the contact stage's CCD: the CCD separation as thickness, the
/// kernels' toi tolerance and the distance filter's depth.
DetectOptions ccd_detect_options(const ContactOptions& o);

}  // namespace clothcd::sim::detail
