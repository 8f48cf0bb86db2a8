#pragma once
// The research options on the self detector's core: the checks they add and the node test and
// cones they set (src/detect/self_core.hpp), for research::SelfDetector and detect_each.

#include <span>
#include <vector>

#include "clothcd/research/options.hpp"
#include "detect/positions.hpp"
#include "detect/self_core.hpp"

namespace clothcd::research {

/// Refuses research options a detection cannot honour (InputError): an unsound rule with a reuse
/// distance (the rule may cull the pairs the distance keeps).
void check_research(const DetectOptions& o);

/// Puts the options on the core: the product's part as they are (not checked here), the node
/// test of culling_rule(o) and the optimal cones of o.research.
void use(detail::SelfCore& core, const DetectOptions& o);

/// SelfDetector::detect_each on the core (detect_each.cpp).
[[nodiscard]] std::vector<clothcd::DetectResult> detect_each_on(
    detail::SelfCore& core, detail::PointsIn p0, detail::PointsIn p1,
    std::span<const DetectOptions> configs);

}  // namespace clothcd::research
