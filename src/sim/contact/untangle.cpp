// Cloth vertices found inside the body move out of it.
#include "sim/contact/untangle.hpp"

#include <algorithm>

namespace clothcd::sim::detail {

// The body's faces are wound counter-clockwise seen from outside (the mannequin's signed volume
// is positive), so a cloth vertex of a face crossing body face g that lies behind g's plane is
// inside the body. Each such vertex escapes along the outward normal of the deepest face it is
// behind, to the repulsion distance in front of it.
void Escapes::find(const ContactGeometry& g, const std::vector<std::pair<int, int>>& crossing_body,
                   double thickness, double untangle_step) {
  escapes_.clear();
  escaping_.assign(g.x0.size(), 0);
  if (crossing_body.empty() || !(untangle_step > 0)) return;
  const auto& cf = g.cloth().faces();
  const auto& bf = g.body().faces();
  std::vector<int> slot(g.x0.size(), -1);
  for (const auto& [f, k] : crossing_body) {
    const Face& t = bf[k];
    Vec3 n = (g.b0[t[1]] - g.b0[t[0]]).cross(g.b0[t[2]] - g.b0[t[0]]);
    if (!normalize(n)) continue;
    for (int i : cf[f]) {
      const double depth = n.dot(g.x0[i] - g.b0[t[0]]);
      if (!(depth < 0.0) || g.inv_mass[i] == 0.0) continue;
      const double push = thickness - depth;
      if (slot[i] < 0) {
        slot[i] = static_cast<int>(escapes_.size());
        escapes_.push_back({i, k, n, push});
      } else if (push > escapes_[slot[i]].push) {
        escapes_[slot[i]] = {i, k, n, push};
      }
    }
  }
  for (const Escape& e : escapes_)
    escaping_[e.vertex] = 1;
}

// Self CCD still guards the escaping vertices' motion against the rest of the cloth.
void Escapes::apply(const ContactGeometry& g, std::span<Vec3> v, double untangle_step) const {
  for (const Escape& e : escapes_) {
    const Face& t = g.body().faces()[e.body_face];
    const Vec3 vg = (g.vb[t[0]] + g.vb[t[1]] + g.vb[t[2]]) / 3.0;
    const double target = std::min(e.push, untangle_step) / g.h;
    const double vn = e.n.dot(v[e.vertex] - vg);
    if (vn < target) v[e.vertex] += (target - vn) * e.n;
  }
}

}  // namespace clothcd::sim::detail
