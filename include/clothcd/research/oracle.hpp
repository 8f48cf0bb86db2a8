#pragma once
/// @file
/// Brute-force references of the detectors (the research module's oracle): every VF and EE
/// feature pair of the mesh (or meshes), each put through the same feature box test, filters and
/// kernel as the detectors. Quadratic: for tests and measurements only.

#include "clothcd/detect/detector.hpp"

namespace clothcd::research {

/// All pairs of features that touch during v_t0 -> v_t1; `active` (optional, per face) restricts
/// to pairs with at least one feature on an active face. Stats hold the test counts only.
[[nodiscard]] clothcd::DetectResult brute_force_detect(const Topology& topology,
                                                       const Positions& v_t0, const Positions& v_t1,
                                                       const clothcd::DetectOptions& options = {},
                                                       std::span<const std::uint8_t> active = {});

/// Brute-force two-mesh reference of PairDetector.
[[nodiscard]] PairDetectResult brute_force_detect_pair(const Topology& a, const Positions& a_t0,
                                                       const Positions& a_t1, const Topology& b,
                                                       const Positions& b_t0, const Positions& b_t1,
                                                       const clothcd::DetectOptions& options = {});

}  // namespace clothcd::research
