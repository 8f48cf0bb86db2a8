#pragma once
// CSV form of the experiment's records (one header line, comma-separated, no quoting: names are
// sanitized).

#include <filesystem>
#include <string>
#include <vector>

#include "clothcd/experiment/experiment.hpp"

namespace clothcd::experiment::detail {

[[nodiscard]] std::string step_rows_csv(const std::vector<StepRow>& rows);
[[nodiscard]] std::string timing_rows_csv(const std::vector<TimingRow>& rows);
[[nodiscard]] std::string spread_rows_csv(const std::vector<SpreadRow>& rows);

}  // namespace clothcd::experiment::detail
