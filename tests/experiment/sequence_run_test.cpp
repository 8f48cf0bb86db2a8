// Whole-sequence runs of the experiment harness on small procedural sequences: every E-th call,
// the timing pass (repeats x thread counts x configurations, interleaved), crossing-pair counts
// against the brute-force intersection oracle, manifest counts, and the stamped reports.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include "clothcd/experiment/experiment.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/sim/intersections.hpp"
#include "support/files.hpp"

namespace {

namespace fs = std::filesystem;
using namespace clothcd;
using namespace clothcd::experiment;

fs::path sequence_temp_dir(const std::string& name) {
  return clothcd::test::fresh_temp_dir("clothcd_sequence_run_test", name);
}

using clothcd::test::slurp;

std::vector<StepRow> rows_of(const ExperimentOptions& opt, const Sequence& seq, const char* b) {
  return read_step_rows(opt.out / "runs" / seq.name / (std::string(b) + ".csv"));
}

TEST(ExperimentSequence, EveryEthCallRunsThoseFramePairsOnly) {
  Sequence all = folding_sheet(8, 5);
  Sequence strided = all;
  strided.every = 2;
  ExperimentOptions opt;
  opt.builds = {BvhBuild::Patch};
  opt.optimal_every = 1;
  opt.out = sequence_temp_dir("every_all");
  run_sequence(all, opt);
  const auto full = rows_of(opt, all, "patch");
  const auto full_spread = read_spread_rows(opt.out / "runs" / all.name / "patch.spread.csv");
  fs::remove_all(opt.out);

  opt.out = sequence_temp_dir("every_2");
  int ran = 0;
  run_sequence(strided, opt, [&](const Progress& p) { ran += p.ran ? 1 : 0; });
  EXPECT_EQ(ran, 3);  // calls 0, 2, 4 of 5
  const auto part = rows_of(opt, strided, "patch");
  std::set<int> steps;
  for (const auto& r : part)
    steps.insert(r.step);
  EXPECT_EQ(steps, (std::set<int>{0, 2, 4}));
  EXPECT_EQ(part.size(), 3u * 10u);
  // Each call run is the same frame pair as in the full run: the same counts and collisions.
  for (const auto& r : part) {
    const auto it = std::find_if(full.begin(), full.end(), [&](const StepRow& f) {
      return f.step == r.step && f.culling == r.culling && f.policy == r.policy;
    });
    ASSERT_NE(it, full.end());
    EXPECT_EQ(r.triangle_pairs, it->triangle_pairs) << r.step << r.culling << r.policy;
    EXPECT_EQ(r.vf_collisions, it->vf_collisions);
    EXPECT_EQ(r.ee_collisions, it->ee_collisions);
    EXPECT_EQ(r.missed_vf + r.missed_ee, it->missed_vf + it->missed_ee);
  }
  // OPTIMAL every run call (optimal_every counts the calls run), the same angles as before.
  const auto spread = read_spread_rows(opt.out / "runs" / strided.name / "patch.spread.csv");
  int optimal = 0;
  for (const auto& r : spread) {
    if (r.policy != "OPTIMAL") continue;
    ++optimal;
    const auto it = std::find_if(full_spread.begin(), full_spread.end(), [&](const SpreadRow& f) {
      return f.step == r.step && f.policy == r.policy;
    });
    ASSERT_NE(it, full_spread.end());
    EXPECT_EQ(r.node_angle, it->node_angle);
    EXPECT_EQ(r.internal_mean, it->internal_mean);
  }
  EXPECT_EQ(optimal, 3);

  // The reports say how many calls of how many were run.
  write_reports({strided}, opt);
  const std::string summary = slurp(opt.out / "summary.md");
  EXPECT_NE(summary.find("| fold | 128 | 6 | 5 | 3 |"), std::string::npos) << summary;
  EXPECT_NE(slurp(opt.out / "table1.md").find("3 of its 5 CD calls: every 2nd"), std::string::npos);
  fs::remove_all(opt.out);
}

TEST(ExperimentSequence, TimingPassRepeatsEveryConfigurationPerThreadCount) {
  const Sequence seq = folding_sheet(6, 4);
  ExperimentOptions opt;
  opt.out = sequence_temp_dir("timing");
  opt.builds = {BvhBuild::Spatial};
  opt.optimal_every = 0;
  opt.timing_every = 3;  // calls 0 and 3
  opt.timing_repeats = 2;
  opt.timing_threads = {1, 2};
  opt.timing_cullings = {CullingRule::Sound};
  run_sequence(seq, opt);
  const fs::path file = opt.out / "runs" / seq.name / "spatial.timing.csv";
  const auto rows = read_timing_rows(file);
  // (reference + 3 policies under sound) x 2 repeats x 2 thread counts, on 2 steps.
  ASSERT_EQ(rows.size(), 4u * 2u * 2u * 2u);
  std::map<std::tuple<int, std::string, std::string, int>, int> count;
  std::map<int, std::vector<std::string>> first_of_repeat;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    EXPECT_TRUE(r.step == 0 || r.step == 3) << r.step;
    EXPECT_TRUE(r.culling == "sound" || (r.culling == "none" && r.policy == "-"));
    EXPECT_GE(r.threads, 1);
    EXPECT_LE(r.threads, 2);
    EXPECT_GE(r.ms_total(), 0.0);
    ++count[{r.step, r.culling, r.policy, r.threads}];
    if (i % 4 == 0) first_of_repeat[r.step].push_back(r.culling + r.policy);
  }
  for (const auto& [key, n] : count)
    EXPECT_EQ(n, 2) << std::get<0>(key) << std::get<1>(key) << std::get<2>(key);
  // The order rotates per repeat: repeat 1 does not start with repeat 0's first configuration.
  for (const auto& [step, firsts] : first_of_repeat) {
    ASSERT_EQ(firsts.size(), 4u);  // 2 repeats x 2 thread counts
    EXPECT_EQ(firsts[0], firsts[1]);
    EXPECT_NE(firsts[0], firsts[2]);
  }
  // A rerun finds the timed steps and does not time them again.
  run_sequence(seq, opt);
  EXPECT_EQ(read_timing_rows(file).size(), rows.size());

  opt.stamp = stamp("clothcd experiment --test", fs::current_path(), "2");
  write_reports({seq}, opt);
  const std::string timing = slurp(opt.out / "timing.md");
  EXPECT_NE(timing.find("- command: `clothcd experiment --test`"), std::string::npos);
  EXPECT_NE(timing.find("- written: load average"), std::string::npos);
  EXPECT_NE(timing.find("| spatial | sound | PROPOSED | 1 | 4 |"), std::string::npos) << timing;
  EXPECT_NE(timing.find("| spatial | sound | PROVOT | 2 | 4 |"), std::string::npos);
  EXPECT_NE(slurp(opt.out / "summary.md").find("- machine: "), std::string::npos);
  const std::string csv = slurp(opt.out / "timing.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), static_cast<long>(rows.size()) + 1);
  fs::remove_all(opt.out);
}

TEST(ExperimentSequence, CrossingsMatchTheBruteForceIntersectionCheck) {
  Sequence seq = folding_sheet(8, 4);
  count_crossings(seq);
  ASSERT_EQ(seq.crossings.size(), seq.frames.size());
  const Topology topo(seq.faces, seq.num_vertices);
  const sim::IntersectionCounter counter(topo, {}, {}, 0);
  long long total = 0;
  for (std::size_t k = 0; k < seq.frames.size(); ++k) {
    std::vector<sim::Vec3> x;
    for (Eigen::Index i = 0; i < seq.frames[k].rows(); ++i)
      x.emplace_back(seq.frames[k].row(i).transpose());
    const long long expect = static_cast<long long>(counter.self_pairs_brute_force(x).size());
    EXPECT_EQ(seq.crossings[k], expect) << "frame " << k;
    total += expect;
  }
  EXPECT_EQ(seq.crossings.front(), 0) << "the flat sheet crosses nothing";
  EXPECT_GT(total, 0) << "the folded layers pass through each other";

  const auto before = seq.crossings;
  drop_frames_before(seq, 2);
  EXPECT_EQ(seq.frames.size(), before.size() - 2);
  EXPECT_EQ(seq.crossings, std::vector<long long>(before.begin() + 2, before.end()));
}

TEST(ExperimentSequence, SimulatorFoldersCarryTheManifestsCounts) {
  const Sequence seq = folding_sheet(4, 2);
  const fs::path dir = sequence_temp_dir("manifest");
  for (int k = 0; k <= seq.steps(); ++k) {
    TriangleMesh m;
    m.faces = seq.faces;
    for (Eigen::Index i = 0; i < seq.frames[k].rows(); ++i)
      m.vertices.push_back(seq.frames[k].row(i).transpose());
    write_obj(dir / (std::string("frame_000") + std::to_string(k) + ".obj"), m);
  }
  nlohmann::json man{
      {"complete_frames", 2},
      {"mesh_format", "obj"},
      {"initial_self_intersections", 0},
      {"frames",
       {{{"frame", 1}, {"self_intersections", 7}}, {{"frame", 2}, {"self_intersections", 0}}}}};
  std::ofstream(dir / "manifest.json") << man.dump();
  Sequence back = load_frame_folder(dir);
  EXPECT_EQ(back.crossings, (std::vector<long long>{0, 7, 0}));
  EXPECT_NE(back.crossings_how.find("manifest"), std::string::npos);
  count_crossings(back);  // already counted: kept
  EXPECT_EQ(back.crossings, (std::vector<long long>{0, 7, 0}));
  // A manifest without the counts: nothing is read, count_crossings counts.
  man.erase("initial_self_intersections");
  std::ofstream(dir / "manifest.json") << man.dump();
  back = load_frame_folder(dir);
  EXPECT_TRUE(back.crossings.empty());
  count_crossings(back);
  EXPECT_EQ(back.crossings.size(), 3u);
  fs::remove_all(dir);
}

}  // namespace
