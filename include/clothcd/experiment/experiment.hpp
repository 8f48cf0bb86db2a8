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

namespace clothcd::experiment {

[[nodiscard]] std::string policy_name(ConePolicy p);  ///< PROVOT, PROPOSED, EXACT, OPTIMAL
[[nodiscard]] std::string culling_name(Culling c);    ///< none, cone, gated, sound
[[nodiscard]] std::string build_name(BvhBuild b);     ///< spatial, patch
/// Case-insensitive parsers; throw InputError naming `option` and the accepted values.
[[nodiscard]] ConePolicy parse_policy(const std::string& s, const std::string& option);
[[nodiscard]] Culling parse_culling(const std::string& s, const std::string& option);
[[nodiscard]] BvhBuild parse_build(const std::string& s, const std::string& option);

struct ExperimentOptions {
  std::filesystem::path out;
  /// Policies run with every culling rule (OPTIMAL is not allowed here: its refit is slow and it
  /// is measured for the spread angles only).
  std::vector<ConePolicy> policies{ConePolicy::Provot, ConePolicy::Proposed, ConePolicy::Exact};
  std::vector<Culling> cullings{Culling::Cone, Culling::Gated, Culling::Sound};
  std::vector<BvhBuild> builds{BvhBuild::Spatial, BvhBuild::Patch};
  /// OPTIMAL cones are computed on steps 0, K, 2K, ... (0: never).
  int optimal_every = 10;
  /// No OPTIMAL cones for sequences with more triangles than this (0: no limit): its refit has
  /// no saturation shortcut and takes minutes on large, crumpled garments.
  int optimal_max_faces = 0;
};

/// One CD call of one configuration. `policy` is "-" for the unculled reference (culling none).
/// Counts are the detector's DetectStats; missed = in the reference's pair set and not in this
/// configuration's, extra = the converse (exact (vertex, face) / (edge, edge) sets).
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
/// OUT/table1.md, OUT/table2.md and OUT/misses.md (all atomically).
void write_reports(const std::vector<Sequence>& scenes, const ExperimentOptions& options);

/// Runs the plot script (fig5.png, fig6.png in OUT) with `python`. Returns an empty string on
/// success, else what went wrong (e.g. matplotlib missing); never throws for a failed plot.
[[nodiscard]] std::string run_plots(const std::filesystem::path& out,
                                    const std::filesystem::path& script,
                                    const std::string& python = "/usr/bin/python3");

[[nodiscard]] std::vector<StepRow> read_step_rows(const std::filesystem::path& csv);
[[nodiscard]] std::vector<SpreadRow> read_spread_rows(const std::filesystem::path& csv);

}  // namespace clothcd::experiment
