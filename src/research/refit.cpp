// The research refit (clothcd/research/refit.hpp): the Bvh's own refits, with the optimal cones
// of src/bvh/optimal_cones.hpp for ConeRule::Optimal.

#include "clothcd/research/refit.hpp"

#include "bvh/optimal_cones.hpp"

namespace clothcd::research {
namespace {

// `options` with the policy of `rule` (Optimal: any, the optimal cones ignore it).
RefitOptions with_policy(RefitOptions options, ConeRule rule) {
  if (rule == ConeRule::Provot) options.policy = ConePolicy::Provot;
  if (rule == ConeRule::Proposed) options.policy = ConePolicy::Proposed;
  if (rule == ConeRule::Exact) options.policy = ConePolicy::Exact;
  return options;
}

}  // namespace

void refit(Bvh& bvh, std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
           const RefitOptions& options, ConeRule rule) {
  const RefitOptions o = with_policy(options, rule);
  if (rule == ConeRule::Optimal) {
    detail::OptimalCones::refit(bvh, v_t0, v_t1, o);
  } else {
    bvh.refit(v_t0, v_t1, o);
  }
}

}  // namespace clothcd::research
