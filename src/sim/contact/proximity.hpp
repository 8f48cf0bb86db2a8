#pragma once
// Proximity contacts at the substep start (features within the repulsion distance), the
// constraints and couplings they hand to the dynamics solve, and repulsion with friction on them
// after the solve.

#include <span>
#include <vector>

#include "clothcd/sim/contact_handler.hpp"
#include "sim/contact/detectors.hpp"
#include "sim/contact/geometry.hpp"
#include "sim/contact/untangle.hpp"

namespace clothcd::sim::detail {

class ProximityContacts {
 public:
  ProximityContacts(const ContactOptions& options, const ContactGeometry& geometry)
      : opt_(options), g_(geometry) {}

  /// This substep's contacts: cloth self pairs (seam-linked ones left out), then cloth-body
  /// pairs (escaping vertices' left out), each list in the detectors' sorted order; both
  /// detectors started. Returns what the self query cost (zero without `self`).
  SelfProximityFigures find(ContactDetectors& detectors, const Escapes& escapes, bool self,
                            bool body);
  /// Repulsion and friction (sorted pairs, Gauss-Seidel), sweeping until no pair approaches
  /// faster than its target (one sweep left coupled pairs approaching, and each became a CCD
  /// hit, a constraint and a vertex of every later pass's scope); friction in the first sweep.
  void repel(std::span<Vec3> v) const;

  [[nodiscard]] std::size_t size() const { return contacts_.size(); }
  [[nodiscard]] const std::vector<ContactConstraint>& constraints() const { return constraints_; }
  [[nodiscard]] const std::vector<ContactCoupling>& couplings() const { return couplings_; }

 private:
  void find_body(ContactDetectors& detectors, const Escapes& escapes);
  // The normal velocity repulsion asks of a contact: a share of its overlap per substep.
  [[nodiscard]] double repulsion_target(const Contact& c) const;
  void add_proximity(const Contact& c);
  void add_constraint(const Contact& c);
  bool repel_pointwise(const Contact& c, double target, bool friction, std::span<Vec3> v) const;

  const ContactOptions& opt_;
  const ContactGeometry& g_;
  std::vector<Contact> contacts_;
  std::vector<ContactConstraint> constraints_;  // see add_constraint()
  std::vector<ContactCoupling> couplings_;      // see add_proximity()
  double constraint_gap_ = 0.0;
};

}  // namespace clothcd::sim::detail
