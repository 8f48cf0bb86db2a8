// Projected Gauss-Seidel on the substep's CCD impacts.
#include "sim/contact/projection.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace clothcd::sim::detail {

// The constraints are n . (sum c_k v_k) >= (2 sep - gap) / h with accumulated impulses >= 0,
// i.e. close to the mass-weighted nearest velocities that satisfy every impact found so far. A
// pair hit again keeps its earlier constraints beside the new one, so the linearization's errors
// are fixed by accumulation instead of by the pair flipping between normals. Resolving each
// pass's hits alone would undo earlier passes' work and leave the impact zones to do it.
void ImpactProjection::project(const std::vector<Contact>& hits, std::span<Vec3> v,
                               std::vector<std::uint8_t>& touched) {
  for (const Contact& c : hits) {
    impacts_.push_back(c);
    lambda_.push_back(0.0);
  }
  // The next pass must retest this pass's hits and every pair with a vertex whose velocity the
  // projection changes; every other pair keeps a motion already tested without a hit.
  std::vector<std::pair<int, Vec3>> before;
  for (const Contact& c : impacts_) {
    for (int k = 0; k < 4; ++k) {
      if (!c.on_body[k]) before.emplace_back(c.id[k], v[c.id[k]]);
    }
  }
  std::vector<double> denom(impacts_.size(), 0.0);
  for (std::size_t i = 0; i < impacts_.size(); ++i) {
    for (int k = 0; k < 4; ++k)
      denom[i] += impacts_[i].c[k] * impacts_[i].c[k] * g_.weight(impacts_[i], k);
  }
  const double h = g_.h;
  for (int sweep = 0; sweep < opt_.projection_sweeps; ++sweep) {
    double worst = 0.0;
    for (std::size_t i = 0; i < impacts_.size(); ++i) {
      const Contact& c = impacts_[i];
      if (!(denom[i] > 0.0)) continue;
      // End the substep at least twice the pair's separation apart, or (a pair already that
      // close) no closer than it started.
      const double target = (2.0 * c.sep - c.gap) / h;
      const double vn = c.n.dot(g_.relative_velocity(c, v));
      const double next = std::max(0.0, lambda_[i] + (target - vn) / denom[i]);
      const double dl = next - lambda_[i];
      if (dl == 0.0) continue;
      lambda_[i] = next;
      worst = std::max(worst, std::abs(dl) * denom[i]);
      for (int k = 0; k < 4; ++k) {
        if (!c.on_body[k]) v[c.id[k]] += (c.c[k] * dl * g_.weight(c, k)) * c.n;
      }
    }
    if (worst <= opt_.projection_tolerance * opt_.ccd_thickness / h) break;
  }
  for (const auto& [i, vi] : before) {
    if (v[i] != vi) touched[i] = 1;
  }
  for (const Contact& c : hits) {
    for (int k = 0; k < 4; ++k) {
      if (!c.on_body[k]) touched[c.id[k]] = 1;
    }
  }
}

}  // namespace clothcd::sim::detail
