#pragma once
// Where the shared test data lives: $CLOTHCD_DATA, else ../shared/data beside the project.
// Data-driven tests call CLOTHCD_REQUIRE_DATA(sub) and skip with a message when it is missing.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>

namespace clothcd::test {

inline std::filesystem::path data_root() {
  if (const char* env = std::getenv("CLOTHCD_DATA"); env != nullptr && *env != '\0') return env;
  return CLOTHCD_DATA_DEFAULT;
}

/// The path of `sub` under the data root when it exists.
inline std::optional<std::filesystem::path> data_path(const std::filesystem::path& sub) {
  auto p = data_root() / sub;
  if (std::filesystem::exists(p)) return p;
  return std::nullopt;
}

}  // namespace clothcd::test

/// Declares `var` as the data path of `sub`, or skips the test when that data is absent.
#define CLOTHCD_REQUIRE_DATA(var, sub)                                                         \
  const auto var##_opt = ::clothcd::test::data_path(sub);                                      \
  if (!var##_opt) {                                                                            \
    GTEST_SKIP() << "test data " << (::clothcd::test::data_root() / (sub)).string()            \
                 << " not found; set CLOTHCD_DATA to the shared data folder to run this test"; \
  }                                                                                            \
  const std::filesystem::path& var = *var##_opt
