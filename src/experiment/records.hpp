#pragma once
// CSV form of the experiment's records (one header line, comma-separated, no quoting: names are
// sanitized) and small shared functions.

#include <filesystem>
#include <string>
#include <vector>

#include "clothcd/experiment/experiment.hpp"

namespace clothcd::experiment::detail {

[[nodiscard]] std::string step_rows_csv(const std::vector<StepRow>& rows);
[[nodiscard]] std::string spread_rows_csv(const std::vector<SpreadRow>& rows);

/// Writes `text` to `path` through a temporary file and a rename.
void write_text_atomic(const std::filesystem::path& path, const std::string& text);

}  // namespace clothcd::experiment::detail
