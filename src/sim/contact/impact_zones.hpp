#pragma once
// Impact zones (Provot 1997), the fail-safe after the CCD passes: cloth vertices joined by the
// remaining hits move together by one invertible linear map over the substep, so nothing inside
// a zone can collide.

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "clothcd/sim/collision.hpp"
#include "clothcd/sim/contact_handler.hpp"
#include "sim/contact/geometry.hpp"

namespace clothcd::sim::detail {

/// The CCD hits of the motion x0 -> x0 + h v (restricted to the active vertices when given) at
/// the CCD separation scaled by `sep_scale` (see CcdHits::find).
using ZoneHits = std::function<std::vector<Contact>(
    std::span<const Vec3> v, const std::vector<int>* active, double sep_scale)>;

/// Runs zone rounds until `hits` finds none or `zone_rounds` have run; `changed` flags the
/// vertices the last response moved. The first `margin_rounds` (at most half the rounds) ask
/// for the CCD separation, later ones for no contact (sep_scale 0). Returns the zone figures:
/// zones (of the last round), largest_zone, zone_rounds, and as unresolved the hits left when
/// the rounds ran out.
CollisionStats resolve_zones(const ContactGeometry& g, const ContactOptions& opt,
                             const ZoneHits& hits, std::span<Vec3> v,
                             std::vector<std::uint8_t>& changed);

/// The ids whose flag is set.
std::vector<int> flagged(const std::vector<std::uint8_t>& flag);

}  // namespace clothcd::sim::detail
