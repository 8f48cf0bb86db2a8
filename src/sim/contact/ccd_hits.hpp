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

/// What one CCD pass found and cost.
struct CcdPass {
  std::vector<Contact> contacts;  ///< self hits first, each list in the detector's sorted order
  long long excluded = 0;         ///< hits left out: tangled, or touching at t0
  SelfCcdFigures self_ccd;        ///< of an unrestricted pass with self contact, else zero
  CollisionPartTimes times;       ///< ccd_self_s, ccd_body_s and ccd_hits_s; the rest 0
};

class CcdHits {
 public:
  CcdHits(const ContactOptions& options, const ContactGeometry& geometry,
          ContactDetectors& detectors, const Crossings& crossings, const Escapes& escapes)
      : opt_(options), g_(geometry), det_(detectors), crossings_(crossings), escapes_(escapes) {}

  /// The hits of the motion x0 -> x0 + h v; when `active` is given, only of the pairs with an
  /// active cloth vertex (all other pairs move as when they were last tested without a hit).
  /// `sep_scale` is 1, or 0 in the late zone rounds: there only actual contact (the conservative
  /// kernels at zero separation) still counts, so a zone that keeps every pair apart but cannot
  /// restore the margin is accepted.
  CcdPass find(std::span<const Vec3> v, const std::vector<int>* active, double sep_scale, bool self,
               bool body);

  // What becomes of one hit of a detector.
  struct Hit {
    enum Fate : std::uint8_t { Dropped, Excluded, Kept } fate = Dropped;
    Contact contact;
  };

 private:
  void self_hits(std::span<const Vec3> x1, std::span<const Vec3> v, const std::vector<int>* active,
                 double sep_scale, CcdPass& out);
  void body_hits(std::span<const Vec3> x1, std::span<const Vec3> v, const std::vector<int>* active,
                 double sep_scale, CcdPass& out);
  template <class Query, class Distance, class Make>
  Hit settle(double sep_scale, bool dropped, bool tangled, double toi, const Query& query,
             Distance&& d0, Make&& make, double reach) const;
  [[nodiscard]] double separation(double d0, double sep_scale) const;
  static void gather(std::initializer_list<const std::vector<Hit>*> lists, CcdPass& out);

  const ContactOptions& opt_;
  const ContactGeometry& g_;
  ContactDetectors& det_;
  const Crossings& crossings_;
  const Escapes& escapes_;
};

}  // namespace clothcd::sim::detail
