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

/// The CCD hits of the motion x0 -> x0 + h v (restricted to the active vertices when given).
using ZoneHits =
    std::function<std::vector<Contact>(std::span<const Vec3> v, const std::vector<int>* active)>;

/// Runs zone rounds until `hits` finds none or `zone_rounds` have run (then the hits left are
/// counted as unresolved in `st`); `changed` flags the vertices the last response moved, and
/// `sep_scale` drops to 0 after `margin_rounds` (see CcdHits::sep_scale).
void resolve_zones(const ContactGeometry& g, const ContactOptions& opt, const ZoneHits& hits,
                   double& sep_scale, std::span<Vec3> v, std::vector<std::uint8_t>& changed,
                   CollisionStats& st);

/// The ids whose flag is set.
std::vector<int> flagged(const std::vector<std::uint8_t>& flag);

}  // namespace clothcd::sim::detail
