#pragma once
// Inelastic projection of the velocities onto a substep's CCD impacts (Harmon, Vouga, Tamstorf,
// Grinspun 2008): projected Gauss-Seidel on the linearized constraints, impulses accumulated
// over the substep's passes.

#include <cstdint>
#include <span>
#include <vector>

#include "clothcd/sim/contact_handler.hpp"
#include "sim/contact/geometry.hpp"

namespace clothcd::sim::detail {

class ImpactProjection {
 public:
  ImpactProjection(const ContactOptions& options, const ContactGeometry& geometry)
      : opt_(options), g_(geometry) {}

  /// Forgets the last substep's impacts.
  void clear() {
    impacts_.clear();
    lambda_.clear();
  }
  /// Adds this pass's hits to the substep's impacts and projects v onto all of them at once;
  /// flags in `touched` every cloth vertex of a hit and every vertex whose velocity changed.
  void project(const std::vector<Contact>& hits, std::span<Vec3> v,
               std::vector<std::uint8_t>& touched);

 private:
  const ContactOptions& opt_;
  const ContactGeometry& g_;
  std::vector<Contact> impacts_;  // this substep's impacts so far ...
  std::vector<double> lambda_;    // ... and their accumulated impulses
};

}  // namespace clothcd::sim::detail
