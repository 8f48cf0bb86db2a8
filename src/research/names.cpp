// The research settings' names (clothcd/research/names.hpp), on the detector's name tables.

#include "clothcd/research/names.hpp"

#include "detect/name_table.hpp"

namespace clothcd::research {
namespace {

using detail::name_in;
using detail::parse_in;
using detail::Table;

// The research names: the product's and the research settings, in the order of the paper.
constexpr Table<ConeRule, 4> kConeRules{{{ConeRule::Provot, "provot"},
                                         {ConeRule::Proposed, "proposed"},
                                         {ConeRule::Exact, "exact"},
                                         {ConeRule::Optimal, "optimal"}}};
constexpr Table<CullingRule, 4> kCullingRules{{{CullingRule::None, "none"},
                                               {CullingRule::Cone, "cone"},
                                               {CullingRule::Gated, "gated"},
                                               {CullingRule::Sound, "sound"}}};

}  // namespace

CullingRule culling_rule(const DetectOptions& options) {
  if (options.research.culling) return *options.research.culling;
  return options.culling == Culling::Sound ? CullingRule::Sound : CullingRule::None;
}

void set_culling_rule(DetectOptions& options, CullingRule rule) {
  options.culling = rule == CullingRule::Sound ? Culling::Sound : Culling::None;
  options.research.culling.reset();
  if (unsound(rule)) options.research.culling = rule;
}

namespace {
ConeRule rule_of(ConePolicy policy, bool optimal) {
  if (optimal) return ConeRule::Optimal;
  switch (policy) {
    case ConePolicy::Provot:
      return ConeRule::Provot;
    case ConePolicy::Proposed:
      return ConeRule::Proposed;
    case ConePolicy::Exact:
      break;
  }
  return ConeRule::Exact;
}

void set_rule(ConePolicy& policy, bool& optimal, ConeRule rule) {
  optimal = rule == ConeRule::Optimal;
  if (rule == ConeRule::Provot) policy = ConePolicy::Provot;
  if (rule == ConeRule::Proposed) policy = ConePolicy::Proposed;
  if (rule == ConeRule::Exact) policy = ConePolicy::Exact;
}
}  // namespace

ConeRule cone_rule(const DetectOptions& options) {
  return rule_of(options.policy, options.research.optimal_cones);
}
void set_cone_rule(DetectOptions& options, ConeRule rule) {
  set_rule(options.policy, options.research.optimal_cones, rule);
}

std::string_view to_string(CullingRule rule) {
  return name_in(kCullingRules, rule);
}
std::string_view to_string(ConeRule rule) {
  return name_in(kConeRules, rule);
}
CullingRule parse_culling_rule(std::string_view text, std::string_view what) {
  return parse_in(kCullingRules, text, what);
}
ConeRule parse_cone_rule(std::string_view text, std::string_view what) {
  return parse_in(kConeRules, text, what);
}

}  // namespace clothcd::research
