// Creation, rebuilds and queries of the contact stage's detectors.
#include "sim/contact/detectors.hpp"

#include "sim/fitted_tree.hpp"

namespace clothcd::sim::detail {

DetectOptions ccd_detect_options(const ContactOptions& o) {
  DetectOptions d;
  d.thickness = o.ccd_thickness;
  d.toi_tolerance = o.toi_tolerance;
  d.distance_filter_depth = o.distance_filter_depth;
  d.reuse_front = o.reuse_front;
  return d;
}

void ContactDetectors::start(const SubstepContext& ctx, ContactGeometry& g, bool self, bool body) {
  if (self) start_self(g);
  if (body) start_body(ctx, g);
}

void ContactDetectors::start_self(const ContactGeometry& g) {
  if (!self_) {
    DetectOptions o = ccd_detect_options(opt_);
    // Never the unsound cone rules in the simulator: None or Sound find the same pairs.
    o.culling = opt_.culling == Culling::None ? Culling::None : Culling::Sound;
    o.policy = opt_.cone_policy;
    o.cull_min_triangles = opt_.cull_min_triangles;
    // The patch build: cones cull only nodes whose triangles form a disk, which median splits
    // rarely make, and its subtrees follow the surface, so the unculled traversal and the
    // proximity query are faster on it too (the pairs found are the same).
    o.build = BvhBuild::Patch;
    // The proximity query (at the repulsion distance) then reuses the last CCD pass's pairs.
    o.reuse_distance = opt_.thickness;
    // Seam-linked vertices count as one point: the seam's sides touch by design.
    o.linked_vertices = model_.seam_links();
    self_.emplace(model_.topology().faces(), model_.num_vertices(), g.x0, o);
  } else if (self_fit_ > 0.0 && FittedTree::loosened(self_->bvh().box_area_ratio(), self_fit_)) {
    self_->rebuild(g.x0);  // its boxes are still the last CCD pass's
    self_fit_ = 0.0;
  }
}

void ContactDetectors::start_body(const SubstepContext& ctx, ContactGeometry& g) {
  if (!body_) {
    body_.emplace(model_.topology().faces(), model_.num_vertices(), g.x0, *ctx.body_faces,
                  static_cast<int>(ctx.body_t0.size()), g.b0, ccd_detect_options(opt_));
  }
  g.set_body(&body_->topology_b());
}

ProximityResult ContactDetectors::self_proximity(const ContactGeometry& g, double d) {
  // Unrestricted, which also lets the query reuse the last full CCD pass's pairs.
  self_->clear_active();
  return self_->proximity(g.x0, d);
}

DetectResult ContactDetectors::self_ccd(const ContactGeometry& g, std::span<const Vec3> x1,
                                        const std::vector<int>* active) {
  if (active != nullptr) {
    self_->set_active_vertices(*active);
  } else {
    self_->clear_active();
  }
  DetectResult r = self_->detect(g.x0, x1);
  // The first full pass after a build measures the tree's fit.
  if (active == nullptr && self_fit_ == 0.0) self_fit_ = self_->bvh().box_area_ratio();
  return r;
}

PairProximityResult ContactDetectors::body_proximity(const ContactGeometry& g, double d) {
  body_->clear_active();
  PairProximityResult r = body_->proximity(g.x0, g.b0, d);
  const std::array<double, 2> ratio{body_->bvh_a().box_area_ratio(),
                                    body_->bvh_b().box_area_ratio()};
  if (body_fit_[0] == 0.0) {
    body_fit_ = ratio;
  } else if (FittedTree::loosened(ratio[0], body_fit_[0]) ||
             FittedTree::loosened(ratio[1], body_fit_[1])) {
    body_->rebuild(g.x0, g.b0);
    body_fit_ = {0.0, 0.0};
  }
  return r;
}

PairDetectResult ContactDetectors::body_ccd(const ContactGeometry& g, std::span<const Vec3> x1,
                                            const std::vector<int>* active) {
  if (active != nullptr) {
    body_->set_active_vertices(*active);
  } else {
    body_->clear_active();
  }
  return body_->detect(g.x0, x1, g.b0, g.b1);
}

}  // namespace clothcd::sim::detail
