#pragma once
// Internal: the experiment's records gathered per scene and configuration, and the statistics the
// reports (report.cpp, report_timing.cpp) compute over them.

#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "clothcd/experiment/experiment.hpp"
#include "records.hpp"

namespace clothcd::experiment::detail {

// The paper's Table 1 (average triangle pair tests) and Table 2 (ms: BVH construction, CD,
// total), PROVOT then PROPOSED.
struct PaperRow {
  const char* scene;
  int triangles;
  double pairs_provot, pairs_proposed;
  double bvh_provot, bvh_proposed, cd_provot, cd_proposed, total_provot, total_proposed;
};
inline constexpr PaperRow kPaper[] = {
    {"Ensemble 1", 18920, 39997.78, 30795.03, 3.03, 3.67, 17.17, 12.72, 20.12, 16.39},
    {"Ensemble 2", 34877, 87607.41, 60140.21, 8.52, 11.86, 37.77, 22.10, 46.29, 33.97},
    {"Onepiece 1", 20849, 50518.85, 39499.42, 3.96, 4.61, 18.01, 14.29, 21.97, 18.90},
    {"Onepiece 2", 61949, 165412.73, 122977.72, 11.93, 14.06, 62.69, 48.33, 74.62, 62.40},
};

[[nodiscard]] double mean(const std::vector<double>& v);
[[nodiscard]] double median(std::vector<double> v);
[[nodiscard]] double quantile(std::vector<double> v, double q);

struct Agg {
  int calls = 0;
  std::vector<double> pairs, vf, ee, culled;
  double missed_vf = 0, missed_ee = 0, extra = 0, ref_vf = 0, ref_ee = 0;
  int steps_missing = 0;
};

struct ConfigKey {
  std::string build, culling, policy;
  auto operator<=>(const ConfigKey&) const = default;
};

// Configurations in table order: per build, the reference, then culling-major, policy-minor.
[[nodiscard]] std::vector<ConfigKey> config_order(const ExperimentOptions& opt);

struct SceneData {
  const Sequence* seq = nullptr;
  std::map<ConfigKey, Agg> agg;
  std::vector<StepRow> rows;
  std::vector<SpreadRow> spread;
  std::vector<TimingRow> timing;
};

[[nodiscard]] SceneData collect(const Sequence& seq, const ExperimentOptions& opt);

/// "2nd", "3rd", "4th", "11th", "21st".
[[nodiscard]] std::string ordinal(int n);
/// CD calls run of a sequence (Sequence::every).
[[nodiscard]] int calls_run(const Sequence& seq, const ExperimentOptions& opt);
/// "## name (triangles, CD calls)" and the frames' source, above each scene's table.
[[nodiscard]] std::string scene_heading(const SceneData& d, const ExperimentOptions& opt);

// Per (build, culling, policy, threads): the totals of the timing pass and, paired call by call
// (same step, repeat and thread count), the ratio to PROVOT under the same rule.
struct TimingAgg {
  std::vector<double> total, refit, cd, ratio;
  std::map<int, std::vector<double>> step_totals;  ///< the repeats of each timed step
};
using TimingKey = std::tuple<std::string, std::string, std::string, int>;

[[nodiscard]] std::map<TimingKey, TimingAgg> timing_aggs(const SceneData& d);

// A figure is flagged noisy when the same call, repeated, varies by more than a fifth of its
// median (the steps differ in cost by themselves, so the spread over all calls would not say).
inline constexpr double kNoisy = 0.2;

/// Median over the timed steps of (max - min) / median of that step's repeats.
[[nodiscard]] double repeat_spread(const TimingAgg& a);
/// The interquartile range of v is over kNoisy of its median.
[[nodiscard]] bool noisy(const std::vector<double>& v);

/// Table 2 (means of the timing pass) and the timing report (medians, spreads, paired ratios):
/// report_timing.cpp.
[[nodiscard]] std::string table2(const std::vector<SceneData>& data, const ExperimentOptions& opt);
[[nodiscard]] std::string timing_table(const std::vector<SceneData>& data,
                                       const ExperimentOptions& opt);

}  // namespace clothcd::experiment::detail
