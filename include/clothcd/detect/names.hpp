#pragma once
/// @file
/// The names of the detector's options, as the command-line tool, the Python module, the scene
/// files and the experiment files spell them: one mapping, both ways.
///
///   ConePolicy: provot, proposed, exact
///   Culling:    none, sound
///   BvhBuild:   spatial, patch
///
/// Names are lower case; parsing ignores case, so the paper's PROVOT and PROPOSED are accepted.
/// The research module's settings (clothcd/research/names.hpp) extend these names.

#include <string_view>

#include "clothcd/detect/types.hpp"

namespace clothcd {

[[nodiscard]] std::string_view to_string(ConePolicy policy);
[[nodiscard]] std::string_view to_string(Culling culling);
[[nodiscard]] std::string_view to_string(BvhBuild build);

/// Parse a name (any case). Throws InputError "WHAT: unknown value 'TEXT' (one of a, b, ...)",
/// `what` naming the option the text came from (e.g. "--policy").
[[nodiscard]] ConePolicy parse_cone_policy(std::string_view text,
                                           std::string_view what = "cone policy");
[[nodiscard]] Culling parse_culling(std::string_view text, std::string_view what = "culling");
[[nodiscard]] BvhBuild parse_bvh_build(std::string_view text, std::string_view what = "bvh");

}  // namespace clothcd
