#pragma once
// CSV form of the experiment's records (one header line, comma-separated, no quoting: names are
// sanitized).

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "clothcd/experiment/experiment.hpp"

namespace clothcd::experiment::detail {

[[nodiscard]] std::string step_rows_csv(const std::vector<StepRow>& rows);
[[nodiscard]] std::string timing_rows_csv(const std::vector<TimingRow>& rows);
[[nodiscard]] std::string spread_rows_csv(const std::vector<SpreadRow>& rows);

/// One scene's self-CCD figures under one setting of `clothcd experiment --in-situ`, summed over
/// its frames (in_situ.csv: one row per scene, setting and frame).
struct InSituTotals {
  int frames = 0;
  double substeps = 0, calls = 0, triangle_pairs = 0, nodes_culled = 0;
  double refit_s = 0, traversal_s = 0, narrow_s = 0;
};
/// Keyed by (scene, setting), settings as the in-situ run names them (none, PROVOT, ...).
[[nodiscard]] std::map<std::pair<std::string, std::string>, InSituTotals> read_in_situ(
    const std::filesystem::path& csv);

/// Sections of table1.md / table2.md from the in-situ figures: pair tests and CD time per
/// self-CCD call inside the simulator (one call per substep), by scene and setting.
[[nodiscard]] std::string in_situ_pairs_section(
    const std::map<std::pair<std::string, std::string>, InSituTotals>& totals);
[[nodiscard]] std::string in_situ_times_section(
    const std::map<std::pair<std::string, std::string>, InSituTotals>& totals);

}  // namespace clothcd::experiment::detail
