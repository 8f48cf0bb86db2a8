// Proximity contacts, their constraints and couplings, and repulsion with friction.
#include "sim/contact/proximity.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "sim/contact/part_clock.hpp"

namespace clothcd::sim::detail {

SelfProximityFigures ProximityContacts::find(ContactDetectors& detectors, const Escapes& escapes,
                                             bool self, bool body) {
  contacts_.clear();
  constraints_.clear();
  couplings_.clear();
  const std::span<const Vec3> none;
  SelfProximityFigures f;
  if (self) {
    const ProximityResult r = [&] {
      PartClock clock(f.query_s);
      return detectors.self_proximity(g_, opt_.thickness);
    }();
    ++f.calls;
    f.reused_pairs += static_cast<long long>(r.reused_pairs);
    f.pairs += static_cast<long long>(r.vf.size() + r.ee.size());
    for (const auto& p : r.vf) {
      Contact c;
      if (g_.make_vf(c, p.vertex, false, p.face, false, 0.0, none)) add_proximity(c);
    }
    for (const auto& p : r.ee) {
      Contact c;
      if (g_.make_ee(c, p.edge_a, false, p.edge_b, false, 0.0, none)) add_proximity(c);
    }
  }
  if (body) find_body(detectors, escapes);
  return f;
}

// (cloth vertex, body face) pairs also give constraints, the others couplings.
void ProximityContacts::find_body(ContactDetectors& detectors, const Escapes& escapes) {
  const std::span<const Vec3> none;
  const PairProximityResult r = detectors.body_proximity(g_, opt_.thickness);
  const auto& cf = g_.cloth().faces();
  const auto& ce = g_.cloth().edges();
  for (const auto& p : r.vf_a_on_b) {
    Contact c;
    if (!escapes.vertex(p.vertex) && g_.make_vf(c, p.vertex, false, p.face, true, 0.0, none)) {
      contacts_.push_back(c);
      if (opt_.body_constraints) add_constraint(c);
    }
  }
  for (const auto& p : r.vf_b_on_a) {
    Contact c;
    if (!escapes.face(cf[p.face]) && g_.make_vf(c, p.vertex, true, p.face, false, 0.0, none)) {
      add_proximity(c);
    }
  }
  for (const auto& p : r.ee) {
    Contact c;
    if (!escapes.edge(ce[p.edge_a]) && g_.make_ee(c, p.edge_a, false, p.edge_b, true, 0.0, none)) {
      add_proximity(c);
    }
  }
}

double ProximityContacts::repulsion_target(const Contact& c) const {
  return opt_.repulsion_fraction * (opt_.thickness - c.gap) / g_.h;
}

// A proximity contact that no constraint covers; with `coupled_contacts` also a coupling of the
// solve: the same target as repulsion, the body points' velocity over the substep as a constant.
void ProximityContacts::add_proximity(const Contact& c) {
  contacts_.push_back(c);
  if (!opt_.coupled_contacts) return;
  ContactCoupling cc;
  cc.n = c.n;
  cc.normal_velocity = repulsion_target(c);
  for (int k = 0; k < 4; ++k) {
    cc.c[k] = c.c[k];
    if (c.on_body[k]) {
      cc.body_velocity += c.c[k] * c.n.dot(g_.b1[c.id[k]] - g_.b0[c.id[k]]) / g_.h;
    } else {
      cc.vertex[k] = c.id[k];
    }
  }
  couplings_.push_back(cc);
}

// Keeps, per cloth vertex, the constraint of its nearest body face (contacts come sorted by
// vertex). The body point's normal velocity over the substep plus the repulsion target.
void ProximityContacts::add_constraint(const Contact& c) {
  const int v = c.id[0];
  if (!(g_.inv_mass[v] > 0)) return;
  Vec3 vb_point = Vec3::Zero();
  for (int k = 1; k < 4; ++k)
    vb_point -= c.c[k] * (g_.b1[c.id[k]] - g_.b0[c.id[k]]) / g_.h;
  const double target = repulsion_target(c);
  const ContactConstraint cc{v, c.n, c.n.dot(vb_point) + target};
  if (!constraints_.empty() && constraints_.back().vertex == v) {
    if (c.gap < constraint_gap_) {
      constraints_.back() = cc;
      constraint_gap_ = c.gap;
    }
    return;
  }
  constraints_.push_back(cc);
  constraint_gap_ = c.gap;
}

void ProximityContacts::repel(std::span<Vec3> v) const {
  for (int sweep = 0; sweep < opt_.repulsion_sweeps; ++sweep) {
    bool any = false;
    for (const Contact& c : contacts_) {
      const double target = repulsion_target(c);
      const bool friction = sweep == 0 && opt_.friction > 0;
      if (opt_.pointwise_repulsion && repel_pointwise(c, target, friction, v)) any = true;
      const Vec3 rel = g_.relative_velocity(c, v);
      const double vn = c.n.dot(rel);
      if (vn >= target) continue;
      const double dn = target - vn;
      if (!g_.impulse(c, c.n, dn, v)) continue;
      any = true;
      if (!friction) continue;
      const Vec3 vt = rel - vn * c.n;
      const double lt = vt.norm();
      if (lt > 0) g_.impulse(c, -vt / lt, std::min(opt_.friction * dn, lt), v);
    }
    if (!any) break;
  }
}

// Repulsion point by point: every cloth vertex of one side (weight >= pointwise_weight) keeps the
// other side's cloth vertices, or its body point, from approaching faster than the contact's
// target; the weighted sum of these is the contact's own condition, which the caller then tops
// up for the light-weight vertices left out. Why: the contact's single impulse, spread by weight
// over inverse mass, gives the vertex nearest the contact point a velocity change larger than
// the contact's deficit: a vertex already stopped by its own body contact would be thrown off
// because its face's other two vertices still fall onto a body vertex, and the membrane would
// pull it back (docs/simulator.md 3.1). Returns whether an impulse was applied.
bool ProximityContacts::repel_pointwise(const Contact& c, double target, bool friction,
                                        std::span<Vec3> v) const {
  // Side 0: c_k > 0; side 1: c_k < 0. A body side acts as one point: its weighted velocity.
  std::array<std::array<int, 4>, 2> pts{};
  std::array<int, 2> count{};
  std::array<Vec3, 2> body_v{Vec3::Zero(), Vec3::Zero()};
  std::array<bool, 2> body{false, false};
  for (int k = 0; k < 4; ++k) {
    if (c.c[k] == 0.0) continue;
    const int side = c.c[k] > 0 ? 0 : 1;
    if (c.on_body[k]) {
      body[side] = true;
      body_v[side] += std::abs(c.c[k]) * g_.vb[c.id[k]];
    } else if (std::abs(c.c[k]) >= opt_.pointwise_weight && g_.inv_mass[c.id[k]] > 0) {
      pts[side][count[side]++] = c.id[k];
    }
  }
  if (body[0]) count[0] = 1;
  if (body[1]) count[1] = 1;
  bool any = false;
  for (int a = 0; a < count[0]; ++a) {
    for (int b = 0; b < count[1]; ++b) {
      const int i = body[0] ? -1 : pts[0][a];
      const int j = body[1] ? -1 : pts[1][b];
      const double wi = i < 0 ? 0.0 : g_.inv_mass[i];
      const double wj = j < 0 ? 0.0 : g_.inv_mass[j];
      if (!(wi + wj > 0)) continue;
      const Vec3 rel = (i < 0 ? body_v[0] : v[i]) - (j < 0 ? body_v[1] : v[j]);
      const double vn = c.n.dot(rel);
      if (vn >= target) continue;
      const double dn = target - vn;
      Vec3 d = (dn / (wi + wj)) * c.n;  // impulse
      if (friction) {
        const Vec3 vt = rel - vn * c.n;
        const double lt = vt.norm();
        if (lt > 0) d -= (std::min(opt_.friction * dn, lt) / (wi + wj) / lt) * vt;
      }
      if (i >= 0) v[i] += wi * d;
      if (j >= 0) v[j] -= wj * d;
      any = true;
    }
  }
  return any;
}

}  // namespace clothcd::sim::detail
