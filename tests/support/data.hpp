#pragma once
// Where the shared test data lives: $CLOTHCD_DATA, else ../shared/data beside the project.
// Data-driven tests call CLOTHCD_REQUIRE_DATA(sub): they skip with a message when it is missing,
// except where the environment sets CI, where missing data fails the test (a data test that
// skipped would otherwise leave CI green without having checked anything).

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

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

/// True where the environment variable CI is set to a non-empty value.
inline bool in_ci() {
  const char* env = std::getenv("CI");
  return env != nullptr && *env != '\0';
}

}  // namespace clothcd::test

/// Declares `var` as the data path of `sub`; when that data is absent the test fails under CI
/// and skips elsewhere.
#define CLOTHCD_REQUIRE_DATA(var, sub)                                                            \
  const auto var##_opt = ::clothcd::test::data_path(sub);                                         \
  if (!var##_opt) {                                                                               \
    const std::string missing_ = "test data " + (::clothcd::test::data_root() / (sub)).string() + \
                                 " not found; set CLOTHCD_DATA to the shared data folder";        \
    if (::clothcd::test::in_ci()) GTEST_FAIL() << missing_ << " (CI runs every data test)";       \
    GTEST_SKIP() << missing_ << " to run this test";                                              \
  }                                                                                               \
  const std::filesystem::path& var = *var##_opt
