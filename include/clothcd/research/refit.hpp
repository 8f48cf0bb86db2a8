#pragma once
/// @file
/// A Bvh refit with every cone computation the measurements compare (research::ConeRule), the
/// optimal reference cones included: ConeRule::Optimal gives every internal node the minimal cone
/// of its descendant leaves' normal control directions, from exact leaf caps (docs/cones.md). A
/// node then costs time linear in its triangles, so a refit takes seconds on 100K triangles: for
/// measuring the cone policies, not for simulation. The other rules are Bvh::refit with their
/// ConePolicy. (The research self detector, clothcd/research/detector.hpp, refits the same way.)

#include <Eigen/Core>

#include <span>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/research/options.hpp"

namespace clothcd::research {

/// Bvh::refit(v_t0, v_t1, options) with the cones of `rule` (options.policy is ignored).
void refit(Bvh& bvh, std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
           const RefitOptions& options, ConeRule rule);

}  // namespace clothcd::research
