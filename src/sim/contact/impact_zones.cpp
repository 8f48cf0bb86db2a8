// Impact zones: union-find over the hits' cloth vertices, one affine or rigid motion a zone.
#include "sim/contact/impact_zones.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include "sim/zone_motion.hpp"

namespace clothcd::sim::detail {
namespace {

class UnionFind {
 public:
  explicit UnionFind(int n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int a) {
    while (parent_[a] != a) {
      parent_[a] = parent_[parent_[a]];
      a = parent_[a];
    }
    return a;
  }
  // The smaller id becomes the root, so zones do not depend on the merge order.
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent_[b] = a;
  }

 private:
  std::vector<int> parent_;
};

}  // namespace

std::vector<int> flagged(const std::vector<std::uint8_t>& flag) {
  std::vector<int> ids;
  for (int i = 0; i < static_cast<int>(flag.size()); ++i) {
    if (flag[i]) ids.push_back(i);
  }
  return ids;
}

// Impact zones (Provot 1997), each moved by one invertible linear map; a zone touching the
// body or a pinned vertex follows those anchors (body points have infinite mass).
CollisionStats resolve_zones(const ContactGeometry& g, const ContactOptions& opt,
                             const ZoneHits& hits, std::span<Vec3> v,
                             std::vector<std::uint8_t>& changed) {
  CollisionStats st;
  const std::span<const Vec3> x0 = g.x0, b0 = g.b0;
  const std::span<const double> inv_mass = g.inv_mass;
  const double h = g.h;
  const std::vector<Vec3>& vb = g.vb;
  const int n = g.model().num_vertices();
  UnionFind uf(n);
  std::vector<std::uint8_t> in_zone(n, 0);
  // A cloth vertex, the body point it touches (at t0) and the velocity it must follow there.
  struct Anchor {
    int vertex = -1;
    Vec3 point, velocity;
  };
  std::vector<Anchor> anchors;
  // Per substep: 0.1 mm with the scenes' settings; without the push, zones touching the body
  // leave body crossings behind and stretch the cloth.
  const double anchor_push = std::max(2.0 * opt.ccd_thickness, 0.1 * opt.thickness);
  std::vector<int> vertex_anchor_count(n, 0);
  std::vector<int> active = flagged(changed);
  const auto& mass = g.model().mass();
  // The zones run until no hit is left or for `zone_rounds`. (With zones that bent, an exit
  // after 3 rounds without fewer hits saved time; with rigid zones it cost crossings: twist
  // frames 38-43 had 0 / 0 / 0 / 0 / 5 / 5 crossing pairs without it, 171 by frame 41 with it.)
  for (int round = 0;; ++round) {
    const double sep_scale = round >= std::min(opt.margin_rounds, opt.zone_rounds / 2) ? 0.0 : 1.0;
    const std::vector<Contact> hs = hits(v, opt.full_passes ? nullptr : &active, sep_scale);
    if (hs.empty()) break;
    if (round == opt.zone_rounds) {
      st.unresolved = static_cast<long long>(hs.size());
      break;
    }
    ++st.zone_rounds;
    for (const Contact& c : hs) {
      int first = -1;
      Vec3 body_p = Vec3::Zero(), body_v = Vec3::Zero();
      double body_w = 0.0;
      for (int k = 0; k < 4; ++k) {
        if (c.on_body[k]) {
          body_p += std::abs(c.c[k]) * b0[c.id[k]];
          body_v += std::abs(c.c[k]) * vb[c.id[k]];
          body_w += std::abs(c.c[k]);
          continue;
        }
        in_zone[c.id[k]] = 1;
        if (first < 0) {
          first = c.id[k];
        } else {
          uf.unite(first, c.id[k]);
        }
      }
      if (body_w > 0) {
        for (int k = 0; k < 4; ++k) {
          // Follow the body point, plus a small push out along the contact normal (the cloth
          // side is where its weights point): matching the body's velocity alone keeps a
          // near-zero gap that the body's own deformation then closes.
          if (!c.on_body[k]) {
            const double side = c.c[k] > 0 ? 1.0 : -1.0;
            anchors.push_back(
                {c.id[k], body_p / body_w, body_v / body_w + side * anchor_push / h * c.n});
          }
        }
      }
    }
    // Members of each zone, in vertex order.
    std::vector<std::vector<int>> members;
    std::vector<int> zone_of(n, -1), root_zone(n, -1);
    for (int i = 0; i < n; ++i) {
      if (!in_zone[i]) continue;
      const int r = uf.find(i);
      if (root_zone[r] < 0) {
        root_zone[r] = static_cast<int>(members.size());
        members.emplace_back();
      }
      zone_of[i] = root_zone[r];
      members[zone_of[i]].push_back(i);
    }
    std::fill(vertex_anchor_count.begin(), vertex_anchor_count.end(), 0);
    std::vector<std::vector<int>> zone_anchors(members.size());
    for (std::size_t a = 0; a < anchors.size(); ++a) {
      const int i = anchors[a].vertex;
      zone_anchors[zone_of[i]].push_back(static_cast<int>(a));
      ++vertex_anchor_count[i];
    }
    std::fill(changed.begin(), changed.end(), 0);
    st.zones = static_cast<int>(members.size());
    for (std::size_t z = 0; z < members.size(); ++z) {
      const auto& m = members[z];
      st.largest_zone = std::max(st.largest_zone, static_cast<int>(m.size()));
      bool anchored = !zone_anchors[z].empty();  // touches the body or a pin
      for (int i : m) {
        changed[i] = 1;
        anchored = anchored || inv_mass[i] == 0.0;
      }
      // The zone moves by an invertible linear map of its start positions over the substep, so
      // nothing inside it can collide: free zones move rigidly and keep their momentum and
      // angular momentum (Provot 1997); zones touching the body or a pin take the affine motion
      // closest to the body's velocities at the points they touch (and the pins') where those
      // fix one, else the rigid one (a body that bends is not rigid under a zone). The fit is at
      // the body points, not at the cloth vertices: one contact on a long cloth edge or face
      // would give vertices far apart one velocity. Each vertex following its own anchor would
      // bend the zone, and the zone rounds would stall on self hits inside it.
      std::vector<Vec3> points, velocities;
      std::vector<double> weights;
      for (int i : m) {
        if (!anchored) {
          points.push_back(x0[i]);
          velocities.push_back(v[i]);
          weights.push_back(mass[i]);
        } else if (inv_mass[i] == 0.0) {
          points.push_back(x0[i]);
          velocities.push_back(v[i]);
          weights.push_back(1.0);
        }
      }
      for (int a : zone_anchors[z]) {
        const Anchor& an = anchors[static_cast<std::size_t>(a)];
        points.push_back(an.point);
        velocities.push_back(an.velocity);
        weights.push_back(1.0 / vertex_anchor_count[an.vertex]);
      }
      std::optional<AffineMotion> am;
      if (anchored && opt.affine_zones) am = fit_affine(points, velocities, weights, h);
      const RigidMotion rm = am ? RigidMotion{} : fit_rigid(points, velocities, weights);
      for (int i : m) {
        if (inv_mass[i] != 0.0) v[i] = am ? am->at(x0[i]) : rm.at(x0[i]);
      }
    }
    active = flagged(changed);
  }
  return st;
}

}  // namespace clothcd::sim::detail
