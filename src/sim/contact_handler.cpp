// Collision response, per substep: proximity repulsion and friction, CCD passes with inelastic
// projection, impact zones, untangling of cloth caught inside the body. Each concern lives in
// its own file under contact/; this one runs them in order.
#include "clothcd/sim/contact_handler.hpp"

#include <algorithm>
#include <utility>

#include "sim/contact/ccd_hits.hpp"
#include "sim/contact/crossings.hpp"
#include "sim/contact/detectors.hpp"
#include "sim/contact/geometry.hpp"
#include "sim/contact/impact_zones.hpp"
#include "sim/contact/part_clock.hpp"
#include "sim/contact/projection.hpp"
#include "sim/contact/proximity.hpp"
#include "sim/contact/untangle.hpp"

namespace clothcd::sim {

struct ContactHandler::Impl {
  ContactOptions opt;
  detail::ContactGeometry geometry;
  detail::ContactDetectors detectors;
  detail::Crossings crossings;
  detail::Escapes escapes;
  detail::ProximityContacts proximity;
  detail::CcdHits ccd;
  detail::ImpactProjection projection;
  // What the stages returned since ContactHandler last took it.
  CollisionPartTimes times;
  SelfCcdFigures self_ccd;
  SelfProximityFigures self_proximity;

  Impl(const ClothModel& m, const ContactOptions& o)
      : opt(o),
        geometry(m),
        detectors(m, opt),
        proximity(opt, geometry),
        ccd(opt, geometry, detectors, crossings, escapes),
        projection(opt, geometry) {}

  [[nodiscard]] bool has_body(const SubstepContext& ctx) const {
    return opt.body && ctx.body_faces != nullptr && !ctx.body_t0.empty();
  }

  void prepare(const SubstepContext& ctx) {
    using detail::PartClock;
    const bool body = has_body(ctx);
    {
      PartClock clock(times.setup_s);
      geometry.start(ctx);
      // Before the crossing count too: it and the escapes need the body's topology, which the
      // body detector holds.
      detectors.start(ctx, geometry, opt.self, body);
    }
    {
      PartClock clock(times.crossings_s);
      crossings.find(ctx, geometry, opt.self, body);
      escapes.find(geometry, crossings.body_pairs(), opt.thickness, opt.untangle_step);
    }
    PartClock clock(times.proximity_s);
    self_proximity += proximity.find(detectors, escapes, opt.self, body);
  }

  // One CCD pass; its figures go to `st` (hits left out), self_ccd and `part_times`.
  [[nodiscard]] std::vector<detail::Contact> hits(const SubstepContext& ctx,
                                                  std::span<const Vec3> v,
                                                  const std::vector<int>* active, double sep_scale,
                                                  CollisionStats& st,
                                                  CollisionPartTimes& part_times) {
    detail::CcdPass pass = ccd.find(v, active, sep_scale, opt.self, has_body(ctx));
    st.excluded += pass.excluded;
    self_ccd += pass.self_ccd;
    part_times += pass.times;
    return std::move(pass.contacts);
  }

  CollisionStats respond(const SubstepContext& ctx, std::span<Vec3> v) {
    using detail::PartClock;
    CollisionStats st;
    {
      PartClock clock(times.response_s);
      geometry.start_response(has_body(ctx));
      // 1. Repulsion and friction on the proximity contacts, then escapes out of the body.
      st.proximity_pairs = static_cast<long long>(proximity.size());
      proximity.repel(v);
      escapes.apply(geometry, v, opt.untangle_step);
    }
    // 2. CCD passes with inelastic projection; later passes test only pairs whose motion changed.
    std::vector<std::uint8_t> touched(geometry.model().num_vertices(), 0);
    std::vector<int> active;
    projection.clear();
    // Before the first pass, which tests every pair: what it changes costs no extra pass.
    if (ctx.after_projection) {
      PartClock clock(times.response_s);
      ctx.after_projection(v, touched);
    }
    bool clean = false;
    for (int pass = 0; pass < opt.ccd_iterations; ++pass) {
      const std::vector<detail::Contact> hs =
          hits(ctx, v, pass == 0 || opt.full_passes ? nullptr : &active, 1.0, st, times);
      ++st.ccd_passes;
      st.ccd_hits += static_cast<long long>(hs.size());
      if (hs.empty()) {
        clean = true;
        break;
      }
      PartClock clock(times.response_s);
      std::fill(touched.begin(), touched.end(), 0);
      projection.project(hs, v, touched);
      if (ctx.after_projection) ctx.after_projection(v, touched);
      active = detail::flagged(touched);
    }
    // 3. Impact zones for the hits the passes left.
    if (!clean) {
      // The zones' own time is theirs less that of the CCD passes they run.
      CollisionPartTimes zone_ccd;
      const detail::ZoneHits zone_hits = [&](std::span<const Vec3> vz, const std::vector<int>* act,
                                             double sep_scale) {
        return hits(ctx, vz, act, sep_scale, st, zone_ccd);
      };
      double all = 0.0;
      {
        PartClock clock(all);
        st += detail::resolve_zones(geometry, opt, zone_hits, v, touched);
      }
      times.zones_s += all - zone_ccd.total();
      times += zone_ccd;
    }
    PartClock clock(times.crossings_s);
    crossings.end(geometry, v, st.unresolved == 0 && st.excluded == 0);
    return st;
  }
};

ContactHandler::ContactHandler(const ClothModel& model, const ContactOptions& options)
    : options_(options), impl_(std::make_unique<Impl>(model, options)) {}
ContactHandler::~ContactHandler() = default;

void ContactHandler::prepare(const SubstepContext& ctx) {
  impl_->prepare(ctx);
}

void ContactHandler::contact_couplings(std::vector<ContactCoupling>& out) const {
  out = impl_->proximity.couplings();
}

void ContactHandler::contact_constraints(std::vector<ContactConstraint>& out) const {
  out = impl_->proximity.constraints();
}

SelfCcdFigures& SelfCcdFigures::operator+=(const SelfCcdFigures& o) {
  calls += o.calls;
  triangle_pairs += o.triangle_pairs;
  nodes_culled += o.nodes_culled;
  refit_s += o.refit_s;
  traversal_s += o.traversal_s;
  narrow_s += o.narrow_s;
  return *this;
}

SelfProximityFigures& SelfProximityFigures::operator+=(const SelfProximityFigures& o) {
  calls += o.calls;
  reused_pairs += o.reused_pairs;
  pairs += o.pairs;
  query_s += o.query_s;
  return *this;
}

CollisionPartTimes& CollisionPartTimes::operator+=(const CollisionPartTimes& o) {
  setup_s += o.setup_s;
  crossings_s += o.crossings_s;
  proximity_s += o.proximity_s;
  response_s += o.response_s;
  ccd_self_s += o.ccd_self_s;
  ccd_body_s += o.ccd_body_s;
  ccd_hits_s += o.ccd_hits_s;
  zones_s += o.zones_s;
  return *this;
}

CollisionPartTimes ContactHandler::take_part_times() {
  return std::exchange(impl_->times, {});
}

SelfCcdFigures ContactHandler::take_self_ccd_figures() {
  return std::exchange(impl_->self_ccd, {});
}

SelfProximityFigures ContactHandler::take_self_proximity_figures() {
  return std::exchange(impl_->self_proximity, {});
}

CollisionStats ContactHandler::respond(const SubstepContext& ctx, std::span<Vec3> v_star) {
  return impl_->respond(ctx, v_star);
}

}  // namespace clothcd::sim
