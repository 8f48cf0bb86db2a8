#pragma once
// Name tables of enums, both ways: the one mapping the detector's names and the research
// module's names are spelled with.

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <string>
#include <string_view>
#include <utility>

#include "clothcd/core/error.hpp"

namespace clothcd::detail {

template <class E, std::size_t N>
using Table = std::array<std::pair<E, std::string_view>, N>;

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

}  // namespace clothcd::detail
