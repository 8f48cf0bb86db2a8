#include "clothcd/detect/names.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <string>
#include <utility>

#include "clothcd/core/error.hpp"

namespace clothcd {
namespace {

template <class E, std::size_t N>
using Table = std::array<std::pair<E, std::string_view>, N>;

constexpr Table<ConePolicy, 4> kPolicies{{{ConePolicy::Provot, "provot"},
                                          {ConePolicy::Proposed, "proposed"},
                                          {ConePolicy::Exact, "exact"},
                                          {ConePolicy::Optimal, "optimal"}}};
constexpr Table<Culling, 4> kCullings{{{Culling::None, "none"},
                                       {Culling::Cone, "cone"},
                                       {Culling::Gated, "gated"},
                                       {Culling::Sound, "sound"}}};
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

}  // namespace clothcd
