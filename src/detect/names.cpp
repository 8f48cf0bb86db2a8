#include "clothcd/detect/names.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <string>
#include <utility>

#include "clothcd/core/error.hpp"
#include "clothcd/research/names.hpp"

namespace clothcd {
namespace {

template <class E, std::size_t N>
using Table = std::array<std::pair<E, std::string_view>, N>;

constexpr Table<ConePolicy, 3> kPolicies{{{ConePolicy::Provot, "provot"},
                                          {ConePolicy::Proposed, "proposed"},
                                          {ConePolicy::Exact, "exact"}}};
constexpr Table<Culling, 2> kCullings{{{Culling::None, "none"}, {Culling::Sound, "sound"}}};
// The research names: the tables above and the research settings, in the order of the paper.
constexpr Table<research::ConeRule, 4> kConeRules{{{research::ConeRule::Provot, "provot"},
                                                   {research::ConeRule::Proposed, "proposed"},
                                                   {research::ConeRule::Exact, "exact"},
                                                   {research::ConeRule::Optimal, "optimal"}}};
constexpr Table<research::CullingRule, 4> kCullingRules{{{research::CullingRule::None, "none"},
                                                         {research::CullingRule::Cone, "cone"},
                                                         {research::CullingRule::Gated, "gated"},
                                                         {research::CullingRule::Sound, "sound"}}};
constexpr Table<BvhBuild, 2> kBuilds{{{BvhBuild::Spatial, "spatial"}, {BvhBuild::Patch, "patch"}}};

template <class E, std::size_t N>
std::string_view name_in(const Table<E, N>& table, E value) {
  for (const auto& [v, name] : table) {
    if (v == value) return name;
  }
  return "?";  // only for a value cast from outside the enum
}

template <class E, std::size_t N>
E parse_in(const Table<E, N>& table, std::string_view text, std::string_view what) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::string names;
  for (const auto& [v, name] : table) {
    if (name == lower) return v;
    names += fmt::format("{}{}", names.empty() ? "" : ", ", name);
  }
  throw InputError(fmt::format("{}: unknown value '{}' (one of {})", what, text, names));
}

}  // namespace

std::string_view to_string(ConePolicy policy) {
  return name_in(kPolicies, policy);
}
std::string_view to_string(Culling culling) {
  return name_in(kCullings, culling);
}
std::string_view to_string(BvhBuild build) {
  return name_in(kBuilds, build);
}

ConePolicy parse_cone_policy(std::string_view text, std::string_view what) {
  return parse_in(kPolicies, text, what);
}
Culling parse_culling(std::string_view text, std::string_view what) {
  return parse_in(kCullings, text, what);
}
BvhBuild parse_bvh_build(std::string_view text, std::string_view what) {
  return parse_in(kBuilds, text, what);
}

namespace research {

CullingRule culling_rule(const DetectOptions& options) {
  switch (options.research.unsound_culling) {
    case UnsoundCulling::Cone:
      return CullingRule::Cone;
    case UnsoundCulling::Gated:
      return CullingRule::Gated;
    case UnsoundCulling::None:
      break;
  }
  return options.culling == Culling::Sound ? CullingRule::Sound : CullingRule::None;
}

void set_culling_rule(DetectOptions& options, CullingRule rule) {
  options.culling = rule == CullingRule::Sound ? Culling::Sound : Culling::None;
  options.research.unsound_culling = rule == CullingRule::Cone    ? UnsoundCulling::Cone
                                     : rule == CullingRule::Gated ? UnsoundCulling::Gated
                                                                  : UnsoundCulling::None;
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
void set_cone_rule(RefitOptions& options, ConeRule rule) {
  set_rule(options.policy, options.optimal_cones, rule);
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

}  // namespace research
}  // namespace clothcd
