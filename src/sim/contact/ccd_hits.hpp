#pragma once
// The CCD hits of a substep's motion x0 -> x0 + h v, cloth self and cloth-body, from the
// detectors at the full CCD separation, each settled into a contact at its time of impact, left
// out, or counted as excluded (see settle()).

#include <span>
#include <vector>

#include "clothcd/sim/contact_handler.hpp"
#include "sim/contact/crossings.hpp"
#include "sim/contact/detectors.hpp"
#include "sim/contact/geometry.hpp"
#include "sim/contact/untangle.hpp"

namespace clothcd::sim::detail {

class CcdHits {
 public:
  CcdHits(const ContactOptions& options, const ContactGeometry& geometry,
          ContactDetectors& detectors, const Crossings& crossings, const Escapes& escapes)
      : opt_(options), g_(geometry), det_(detectors), crossings_(crossings), escapes_(escapes) {}

  /// All hits of the motion x0 -> x0 + h v, self ones first, each list in the detector's sorted
  /// order; when `active` is given, only of the pairs with an active cloth vertex (all other
  /// pairs move as when they were last tested without a hit).
  std::vector<Contact> find(std::span<const Vec3> v, const std::vector<int>* active, bool self,
                            bool body);

  /// 1, or 0 in the late zone rounds: there only actual contact (the conservative kernels at
  /// zero separation) still counts, so a zone that keeps every pair apart but cannot restore the
  /// margin is accepted.
  double sep_scale = 1.0;
  /// Hits excluded this substep (tangled, or touching at t0); reset by the caller.
  long long excluded = 0;
  /// Where find() spends its time: ccd_self_s, ccd_body_s and ccd_hits_s grow, the rest stays 0.
  CollisionPartTimes times;

  // What becomes of one hit of a detector.
  struct Hit {
    enum Fate : std::uint8_t { Dropped, Excluded, Kept } fate = Dropped;
    Contact contact;
  };

 private:
  void self_hits(std::span<const Vec3> x1, std::span<const Vec3> v, const std::vector<int>* active,
                 std::vector<Contact>& out);
  void body_hits(std::span<const Vec3> x1, std::span<const Vec3> v, const std::vector<int>* active,
                 std::vector<Contact>& out);
  template <class Query, class Distance, class Make>
  Hit settle(bool dropped, bool tangled, double toi, const Query& query, Distance&& d0, Make&& make,
             double reach) const;
  [[nodiscard]] double separation(double d0) const;
  void gather(std::initializer_list<const std::vector<Hit>*> lists, std::vector<Contact>& out);

  const ContactOptions& opt_;
  const ContactGeometry& g_;
  ContactDetectors& det_;
  const Crossings& crossings_;
  const Escapes& escapes_;
};

}  // namespace clothcd::sim::detail
