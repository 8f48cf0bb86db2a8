#include "clothcd/detect/names.hpp"

#include "detect/name_table.hpp"

namespace clothcd {
namespace {

using detail::name_in;
using detail::parse_in;
using detail::Table;

constexpr Table<ConePolicy, 3> kPolicies{{{ConePolicy::Provot, "provot"},
                                          {ConePolicy::Proposed, "proposed"},
                                          {ConePolicy::Exact, "exact"}}};
constexpr Table<Culling, 2> kCullings{{{Culling::None, "none"}, {Culling::Sound, "sound"}}};
constexpr Table<BvhBuild, 2> kBuilds{{{BvhBuild::Spatial, "spatial"}, {BvhBuild::Patch, "patch"}}};

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

}  // namespace clothcd
