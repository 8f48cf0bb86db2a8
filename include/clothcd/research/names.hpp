#pragma once
/// @file
/// Every culling rule and cone computation the paper's measurements compare, the research ones
/// (clothcd/research/options.hpp) included, as one value each, with the names the command-line
/// tool, the Python module and the experiment files spell them:
///
///   CullingRule: none, cone, gated, sound
///   ConeRule:    provot, proposed, exact, optimal
///
/// Parsing ignores case, so the paper's PROVOT and PROPOSED are accepted. A simulator needs only
/// clothcd/detect/names.hpp, whose names are those of clothcd::DetectOptions. The functions below
/// read and set research::DetectOptions (the product's options and research::Options).

#include <string_view>

#include "clothcd/research/options.hpp"

namespace clothcd::research {

/// The rule a detector with these options runs: research.culling when set, else culling's.
[[nodiscard]] CullingRule culling_rule(const DetectOptions& options);
/// Sets culling and research.culling so that culling_rule(options) == rule: culling alone for
/// the product's rules (research.culling unset), research.culling for an unsound rule (culling
/// then Culling::None).
void set_culling_rule(DetectOptions& options, CullingRule rule);
/// The cones a detector with these options computes: Optimal when research.optimal_cones is set,
/// else policy.
[[nodiscard]] ConeRule cone_rule(const DetectOptions& options);
/// Sets policy and research.optimal_cones so that cone_rule(options) == rule (Optimal leaves
/// policy as it is).
void set_cone_rule(DetectOptions& options, ConeRule rule);

[[nodiscard]] std::string_view to_string(CullingRule rule);
[[nodiscard]] std::string_view to_string(ConeRule rule);

/// Parse a name (any case). Throws InputError "WHAT: unknown value 'TEXT' (one of a, b, ...)",
/// `what` naming the option the text came from (e.g. "--culling").
[[nodiscard]] CullingRule parse_culling_rule(std::string_view text,
                                             std::string_view what = "culling");
[[nodiscard]] ConeRule parse_cone_rule(std::string_view text,
                                       std::string_view what = "cone policy");

}  // namespace clothcd::research
