#pragma once
/// @file
/// The experiment harness: runs every detector configuration (cone policy x culling
/// rule x BVH build, plus the unculled reference) over the very same recorded frames, records
/// every figure per step, and writes the paper's Tables 1-2, a misses table and the data of
/// Figures 5-6. Results are kept per (scene, build) under OUT/runs/ and rewritten atomically
/// after every step, so an interrupted run loses nothing finished and a rerun skips it.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "clothcd/detect/types.hpp"
#include "clothcd/experiment/sequence.hpp"
#include "clothcd/research/names.hpp"

namespace clothcd::experiment {

/// The rules of the experiment: every culling rule and cone computation the paper compares.
using research::ConeRule;
using research::CullingRule;

[[nodiscard]] std::string policy_name(ConePolicy p);    ///< PROVOT, PROPOSED, EXACT
[[nodiscard]] std::string policy_name(ConeRule p);      ///< ... and OPTIMAL
[[nodiscard]] std::string culling_name(CullingRule c);  ///< none, cone, gated, sound
[[nodiscard]] std::string build_name(BvhBuild b);       ///< spatial, patch
/// Case-insensitive parsers; throw InputError naming `option` and the accepted values.
/// parse_policy takes the detection policies: OPTIMAL (measured for the spread angles only, see
/// ExperimentOptions::optimal_every) is refused with a message that says so.
[[nodiscard]] ConePolicy parse_policy(const std::string& s, const std::string& option);
[[nodiscard]] CullingRule parse_culling(const std::string& s, const std::string& option);
[[nodiscard]] BvhBuild parse_build(const std::string& s, const std::string& option);

struct ExperimentOptions {
  std::filesystem::path out;
  /// Policies run with every culling rule (not OPTIMAL: its refit is slow and it is measured for
  /// the spread angles only).
  std::vector<ConePolicy> policies{ConePolicy::Provot, ConePolicy::Proposed, ConePolicy::Exact};
  std::vector<CullingRule> cullings{CullingRule::Cone, CullingRule::Gated, CullingRule::Sound};
  std::vector<BvhBuild> builds{BvhBuild::Spatial, BvhBuild::Patch};
  /// OPTIMAL cones are computed on the run calls 0, K, 2K, ... (see Sequence::every; 0: never).
  int optimal_every = 10;
  /// No OPTIMAL cones for sequences with more triangles than this (0: no limit): its refit has
  /// no saturation shortcut and takes minutes on large, crumpled garments.
  int optimal_max_faces = 0;
  /// Timing pass, on the run calls 0, T, 2T, ... (of those Sequence::every selects) (0: none):
  /// every configuration (the unculled reference, `timing_cullings` x policies) `timing_repeats`
  /// times under each thread count of `timing_threads`, interleaved (repeat-major, then threads,
  /// then configurations in an order rotated per repeat), so load drifts hit all of them alike.
  /// Thread counts are capped by any tbb::global_control the caller holds.
  int timing_every = 0;
  int timing_repeats = 3;
  std::vector<int> timing_threads{1, 2};
  std::vector<CullingRule> timing_cullings{CullingRule::Cone, CullingRule::Gated,
                                           CullingRule::Sound};
  /// Lines written at the top of every report (commit, machine, date, load, ...); see stamp().
  std::string stamp;
};

/// One timed CD call of the timing pass (see ExperimentOptions::timing_every). `load1` is the
/// 1-minute load average read before the step's timing started.
struct TimingRow {
  std::string scene, build, culling, policy;
  int step = 0, threads = 1, repeat = 0;
  double load1 = 0, ms_refit = 0, ms_traverse = 0, ms_narrow = 0;
  [[nodiscard]] double ms_total() const { return ms_refit + ms_traverse + ms_narrow; }
};

/// One CD call of one configuration. `policy` is "-" for the unculled reference (culling none).
/// Counts are the detector's DetectStats; missed = in the reference's pair set and not in this
/// configuration's, extra = the converse (exact (vertex, face) / (edge, edge) sets). The counting
/// pass runs all configurations of a call in one SelfDetector::detect_each: ms_refit is the
/// configuration's own refit, ms_traverse and ms_narrow are NaN (shared work; TimingRow has the
/// times).
struct StepRow {
  std::string scene, build, culling, policy;
  int step = 0;
  double faces = 0, triangle_pairs = 0, vf_tests = 0, ee_tests = 0, vf_np_culled = 0,
         ee_np_culled = 0, box_tests = 0, cone_tests = 0, nodes_culled = 0, contour_tests = 0,
         contour_fails = 0, vf_collisions = 0, ee_collisions = 0, missed_vf = 0, missed_ee = 0,
         extra_vf = 0, extra_ee = 0, ms_refit = 0, ms_traverse = 0, ms_narrow = 0;
  [[nodiscard]] double ms_cd() const { return ms_traverse + ms_narrow; }
  [[nodiscard]] double ms_total() const { return ms_refit + ms_traverse + ms_narrow; }
};

/// Spread angles (degrees) of one policy's cones at one step: of the tracked node (chosen once per
/// scene and build: mid depth, non-saturated PROVOT cone at step 0, the median such angle), the
/// mean over internal nodes (saturated counted as 90), and, on OPTIMAL steps, the mean over the
/// internal nodes whose OPTIMAL cone is not saturated (`opt_domain_mean`, else NaN).
struct SpreadRow {
  std::string scene, build, policy;
  int step = 0;
  int node = -1, node_depth = -1;
  double node_angle = 0, internal_mean = 0, saturated_share = 0;
  double opt_domain_mean = 0;
  int opt_domain_nodes = 0;
  double ms_refit = 0;  ///< this policy's refit (boxes and cones) at this step
};

/// Progress of a run: `done` of `total` (scene, build, step) units; `ran` is false for a unit
/// found complete in OUT and skipped.
struct Progress {
  int done = 0, total = 0;
  bool ran = true;
  std::string what;
};

/// Runs every configuration of `options` over every step of `seq`, appending to OUT/runs/.
void run_sequence(const Sequence& seq, const ExperimentOptions& options,
                  const std::function<void(const Progress&)>& on_progress = {}, int done_before = 0,
                  int total = 0);

/// Reads the runs of the given scenes from OUT/runs/ and writes OUT/steps.csv, OUT/spread.csv,
/// OUT/timing.csv, OUT/table1.md, OUT/table2.md, OUT/timing.md, OUT/misses.md, OUT/spread.md and
/// OUT/summary.md (all atomically). Calls count_crossings-style counts from `scenes` when present.
void write_reports(const std::vector<Sequence>& scenes, const ExperimentOptions& options);

/// Runs the plot script (fig5.png, fig6.png in OUT) with `python`. Returns an empty string on
/// success, else what went wrong (e.g. matplotlib missing); never throws for a failed plot.
[[nodiscard]] std::string run_plots(const std::filesystem::path& out,
                                    const std::filesystem::path& script,
                                    const std::string& python = "/usr/bin/python3");

[[nodiscard]] std::vector<TimingRow> read_timing_rows(const std::filesystem::path& csv);

/// The provenance lines of a report: the command, the commit of `source_dir` (git, "unknown"
/// without it), the machine (cores, CPU model), the worker threads, the UTC date and the load
/// average now (the "before" of a run; write_reports adds the load when it writes).
[[nodiscard]] std::string stamp(const std::string& command, const std::filesystem::path& source_dir,
                                const std::string& threads);
/// The 1, 5 and 15 minute load averages ("unknown" where /proc/loadavg is missing).
[[nodiscard]] std::string load_average();
/// The git commit checked out in `dir`, marked when tracked files have uncommitted changes;
/// "unknown" without git or a repository.
[[nodiscard]] std::string git_commit(const std::filesystem::path& dir);
/// The CPU model from /proc/cpuinfo ("unknown" where it is missing).
[[nodiscard]] std::string cpu_model();
/// The current date and time, "YYYY-MM-DD HH:MM:SS UTC".
[[nodiscard]] std::string utc_now();

/// Rewrites the per-substep ("inside the simulator") sections of table1.md and table2.md in
/// `folder` from the in_situ.csv there (`clothcd experiment --in-situ`), in place, the rest of
/// each table as it was; a table or CSV that is missing is left alone. Returns the tables
/// rewritten. Throws InputError for a malformed CSV.
std::vector<std::filesystem::path> update_in_situ_sections(const std::filesystem::path& folder);
[[nodiscard]] std::vector<StepRow> read_step_rows(const std::filesystem::path& csv);
[[nodiscard]] std::vector<SpreadRow> read_spread_rows(const std::filesystem::path& csv);

}  // namespace clothcd::experiment
