// The experiment harness on a tiny procedural sequence: one row per step x configuration, the
// reference equal to the brute-force oracle, `sound` equal to the reference, resume, tables, plots.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/experiment/experiment.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/research/oracle.hpp"
#include "support/files.hpp"

namespace {

namespace fs = std::filesystem;
using namespace clothcd;
using namespace clothcd::experiment;

fs::path temp_dir(const std::string& name) {
  return clothcd::test::fresh_temp_dir("clothcd_experiment_test", name);
}

using clothcd::test::slurp;

// Every markdown table row has as many cells as its table's header; returns the rows seen.
int check_markdown_tables(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  int header_cells = -1, rows = 0;
  auto cells = [](const std::string& l) {
    return static_cast<int>(std::count(l.begin(), l.end(), '|'));
  };
  while (std::getline(in, line)) {
    if (line.starts_with("|")) {
      if (header_cells < 0) {
        header_cells = cells(line);
      } else {
        EXPECT_EQ(cells(line), header_cells) << line;
        ++rows;
      }
    } else {
      header_cells = -1;
    }
  }
  return rows;
}

TEST(Experiment, FoldingSheetHasSelfCollisions) {
  const Sequence seq = folding_sheet(8, 4);
  EXPECT_EQ(seq.steps(), 4);
  EXPECT_EQ(seq.faces.size(), 128u);
  const Topology topo(seq.faces, seq.num_vertices);
  std::size_t total = 0;
  for (int s = 0; s < seq.steps(); ++s) {
    const DetectResult r = research::brute_force_detect(topo, seq.frames[s], seq.frames[s + 1]);
    total += r.vf.size() + r.ee.size();
  }
  EXPECT_GT(total, 0u) << "the test sequence must exercise the miss accounting";
}

TEST(Experiment, RowsPerStepAndConfigurationSoundEqualsReference) {
  const Sequence seq = folding_sheet(8, 4);
  ExperimentOptions opt;
  opt.out = temp_dir("rows");
  opt.optimal_every = 2;
  opt.timing_every = 2;  // Table 2 comes from the timing pass: calls 0 and 2
  opt.timing_repeats = 1;
  int ran = 0, last_done = 0;
  run_sequence(seq, opt, [&](const Progress& p) {
    ran += p.ran ? 1 : 0;
    last_done = p.done;
  });
  EXPECT_EQ(ran, seq.steps() * 2);
  EXPECT_EQ(last_done, seq.steps() * 2);

  std::vector<StepRow> rows;
  for (const char* b : {"spatial", "patch"}) {
    auto r = read_step_rows(opt.out / "runs" / seq.name / (std::string(b) + ".csv"));
    rows.insert(rows.end(), r.begin(), r.end());
  }
  // 3 policies x 3 cullings + the reference, per build and step, each exactly once.
  ASSERT_EQ(rows.size(), std::size_t(seq.steps()) * 2 * 10);
  std::set<std::tuple<int, std::string, std::string, std::string>> keys;
  for (const auto& r : rows)
    keys.emplace(r.step, r.build, r.culling, r.policy);
  EXPECT_EQ(keys.size(), rows.size());

  // The reference is the oracle's pair count; sound reports exactly the reference's pairs.
  const Topology topo(seq.faces, seq.num_vertices);
  std::map<std::pair<std::string, int>, const StepRow*> ref;
  for (const auto& r : rows) {
    if (r.culling == "none") ref[{r.build, r.step}] = &r;
  }
  ASSERT_EQ(ref.size(), std::size_t(seq.steps()) * 2);
  for (const auto& [key, r] : ref) {
    const DetectResult o =
        research::brute_force_detect(topo, seq.frames[key.second], seq.frames[key.second + 1]);
    EXPECT_EQ(r->vf_collisions, double(o.vf.size())) << key.first << " step " << key.second;
    EXPECT_EQ(r->ee_collisions, double(o.ee.size())) << key.first << " step " << key.second;
    // The paper's narrow phase (no whole-triangle bound): its feature tests and NP culls.
    DetectOptions paper;
    paper.build = key.first == "spatial" ? BvhBuild::Spatial : BvhBuild::Patch;
    paper.distance_filter = false;
    SelfDetector det(seq.faces, seq.num_vertices, seq.frames[0], paper);
    const DetectStats s = det.detect(seq.frames[key.second], seq.frames[key.second + 1]).stats;
    EXPECT_EQ(r->vf_tests, double(s.vf_tests)) << key.first << " step " << key.second;
    EXPECT_EQ(r->ee_tests, double(s.ee_tests)) << key.first << " step " << key.second;
    EXPECT_EQ(r->vf_np_culled, double(s.vf_np_culled)) << key.first << " step " << key.second;
    EXPECT_EQ(r->ee_np_culled, double(s.ee_np_culled)) << key.first << " step " << key.second;
  }
  for (const auto& r : rows) {
    const StepRow& n = *ref.at({r.build, r.step});
    // The counting pass shares its traversal and narrow phase: no CD time is recorded there.
    EXPECT_TRUE(std::isnan(r.ms_traverse) && std::isnan(r.ms_narrow));
    EXPECT_GE(r.ms_refit, 0.0);
    EXPECT_EQ(r.extra_vf + r.extra_ee, 0) << r.build << " " << r.culling << " " << r.policy;
    EXPECT_EQ(r.vf_collisions + r.missed_vf, n.vf_collisions);
    EXPECT_EQ(r.ee_collisions + r.missed_ee, n.ee_collisions);
    EXPECT_LE(r.triangle_pairs, n.triangle_pairs);
    if (r.culling == "sound") {
      EXPECT_EQ(r.missed_vf + r.missed_ee, 0) << r.build << " " << r.policy << " step " << r.step;
    }
  }

  // Spread angles: every policy every step, OPTIMAL on steps 0 and 2, one tracked node; the
  // tight merges never exceed PROVOT's, and the two merge policies never beat OPTIMAL on its
  // domain (OPTIMAL bounds the same control directions; EXACT's exact caps may be tighter).
  const auto spread = read_spread_rows(opt.out / "runs" / seq.name / "spatial.spread.csv");
  ASSERT_EQ(spread.size(), std::size_t(seq.steps()) * 3 + 2);
  std::map<std::pair<int, std::string>, SpreadRow> sp;
  for (const auto& r : spread) {
    EXPECT_EQ(r.node, spread.front().node);
    sp[{r.step, r.policy}] = r;
  }
  for (int s = 0; s < seq.steps(); ++s) {
    EXPECT_LE(sp.at({s, "PROPOSED"}).internal_mean, sp.at({s, "PROVOT"}).internal_mean + 1e-9);
    if (s % 2 == 0) {
      const double o = sp.at({s, "OPTIMAL"}).opt_domain_mean;
      for (const char* p : {"PROVOT", "PROPOSED"})
        EXPECT_GE(sp.at({s, p}).opt_domain_mean, o - 1e-6) << p << " step " << s;
    }
  }

  // A rerun finds everything done and rewrites nothing.
  const std::string before = slurp(opt.out / "runs" / seq.name / "spatial.csv");
  ran = 0;
  run_sequence(seq, opt, [&](const Progress& p) { ran += p.ran ? 1 : 0; });
  EXPECT_EQ(ran, 0);
  EXPECT_EQ(slurp(opt.out / "runs" / seq.name / "spatial.csv"), before);

  // Tables parse (consistent markdown rows) and carry every configuration.
  write_reports({seq}, opt);
  const std::string t1 = slurp(opt.out / "table1.md"), t2 = slurp(opt.out / "table2.md"),
                    mi = slurp(opt.out / "misses.md");
  EXPECT_GE(check_markdown_tables(t1), 20);
  EXPECT_GE(check_markdown_tables(t2), 20);
  EXPECT_GE(check_markdown_tables(mi), 18);
  EXPECT_GE(check_markdown_tables(slurp(opt.out / "spread.md")), 8);
  // Summary: one row per build and culling rule, with PROVOT's misses equal to misses.md's.
  const std::string su = slurp(opt.out / "summary.md");
  // The sequences table (separator + 1 scene), then separator + 2 builds x 3 rules.
  EXPECT_EQ(check_markdown_tables(su), 2 + 7);
  EXPECT_NE(su.find("| spatial | sound | "), std::string::npos);
  EXPECT_NE(t1.find("| spatial | gated | EXACT | 4 |"), std::string::npos);
  // Table 2: per thread count, the two timed calls (one repeat each).
  EXPECT_NE(t2.find("| patch | sound | PROVOT | 1 | 2 |"), std::string::npos) << t2;
  EXPECT_NE(t2.find("| spatial | none | - | 2 | 2 |"), std::string::npos) << t2;
  EXPECT_NE(mi.find("Summary: 0 sound configuration(s) with misses, 0 with extra pairs."),
            std::string::npos);
  EXPECT_EQ(read_step_rows(opt.out / "steps.csv").size(), rows.size());
  fs::remove_all(opt.out);
}

// An in-situ run's per-frame CSV beside the tables adds the per-substep sections: pair tests and
// CD ms per self-CCD call (sums over the frames / calls), PROPOSED against PROVOT and none, the
// paper's rule counted aside beside its 0.75; a later run rewrites those sections alone.
TEST(Experiment, InSituFiguresJoinTables1And2) {
  const Sequence seq = folding_sheet(4, 2);
  ExperimentOptions opt;
  opt.out = temp_dir("in_situ");
  opt.builds = {BvhBuild::Patch};
  opt.optimal_every = 0;
  run_sequence(seq, opt);
  // Two frames per setting: 2 + 3 calls; pairs and seconds chosen so the per-call means are
  // none 200, PROVOT 100, PROPOSED 75, EXACT 75 pairs and 10 / 8 / 6 / 6 ms.
  std::string csv =
      "scene,setting,frame,substeps,frame_s,collision_s,self_ccd_calls,triangle_pairs,"
      "nodes_culled,refit_s,traversal_s,narrow_s,proximity_calls,proximity_reused_pairs,"
      "proximity_pairs,proximity_s\n";
  const std::map<std::string, std::pair<double, double>> per_call{
      {"none", {200, 10}}, {"PROVOT", {100, 8}}, {"PROPOSED", {75, 6}}, {"EXACT", {75, 6}}};
  for (const auto& [setting, v] : per_call) {
    for (int frame = 1, calls = 2; frame <= 2; ++frame, ++calls) {
      const double ms = v.second * calls;
      csv += fmt::format("garment,{},{},{},1.0,0.5,{},{},7,{},{},{},{},0,0,0.0\n", setting, frame,
                         calls, calls, v.first * calls, 1e-3 * ms / 4, 1e-3 * ms / 4, 1e-3 * ms / 2,
                         calls);
    }
  }
  // The paper's rule counted aside: 80 and 60 pairs per call, no times.
  for (const auto& [setting, pairs] : {std::pair{"cone PROVOT", 80}, {"cone PROPOSED", 60}}) {
    for (int frame = 1, calls = 2; frame <= 2; ++frame, ++calls) {
      csv += fmt::format("garment,{},{},{},0,0,{},{},7,0,0,0,0,0,0,0\n", setting, frame, calls,
                         calls, pairs * calls);
    }
  }
  std::ofstream(opt.out / "in_situ.csv") << csv;
  write_reports({seq}, opt);
  const std::string t1 = slurp(opt.out / "table1.md"), t2 = slurp(opt.out / "table2.md");
  check_markdown_tables(t1);
  check_markdown_tables(t2);
  EXPECT_NE(t1.find("| garment | 2 | 5 | 200 | 100 | 75 | 75 | +25.0% | +62.5% | 80 | 60 | 0.750 "
                    "| 0.75 |"),
            std::string::npos)
      << t1;
  EXPECT_NE(t2.find("| garment | 2 | 5 | 10.00 | 8.00 | 6.00 | 6.00 | +25.0% | +40.0% |\n"),
            std::string::npos)
      << t2;

  // An in-situ run rewrites those sections alone (update_in_situ_sections): here with none's
  // pairs four times as many; every other line of the tables stays.
  std::string doubled = csv;
  for (std::size_t at = 0; (at = doubled.find("garment,none,", at)) != std::string::npos;) {
    std::vector<std::string> f;
    const std::size_t end = doubled.find('\n', at);
    std::string line = doubled.substr(at, end - at);
    for (std::size_t p = 0, q; p <= line.size(); p = q + 1) {
      q = std::min(line.find(',', p), line.size());
      f.push_back(line.substr(p, q - p));
    }
    f[7] = fmt::format("{}", 4 * std::stoi(f[7]));
    line = fmt::format("{}", fmt::join(f, ","));
    doubled.replace(at, end - at, line);
    at += line.size();
  }
  std::ofstream(opt.out / "in_situ.csv") << doubled;
  EXPECT_EQ(update_in_situ_sections(opt.out).size(), 2u);
  const std::string u1 = slurp(opt.out / "table1.md"), u2 = slurp(opt.out / "table2.md");
  EXPECT_NE(u1.find("| garment | 2 | 5 | 800 | 100 | 75 | 75 | +25.0% | +90.6% | 80 | 60 |"),
            std::string::npos)
      << u1;
  EXPECT_EQ(u2, t2);  // no time changed
  const std::size_t head = t1.find("## Per simulation substep");
  ASSERT_NE(head, std::string::npos);
  EXPECT_EQ(u1.substr(0, head), t1.substr(0, head));
  EXPECT_EQ(std::count(u1.begin(), u1.end(), '\n'), std::count(t1.begin(), t1.end(), '\n'));

  // A malformed file names itself and the line.
  std::ofstream(opt.out / "in_situ.csv") << csv << "garment,none,3\n";
  try {
    write_reports({seq}, opt);
    ADD_FAILURE() << "no error for a short row";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("in_situ.csv"), std::string::npos) << e.what();
    const auto line = std::count(csv.begin(), csv.end(), '\n') + 1;  // the short row's
    EXPECT_NE(std::string(e.what()).find(fmt::format(":{}:", line)), std::string::npos) << e.what();
  }
  fs::remove_all(opt.out);
}

TEST(Experiment, ResumeRunsOnlyMissingConfigurations) {
  const Sequence seq = folding_sheet(8, 4);
  ExperimentOptions opt;
  opt.out = temp_dir("resume");
  opt.builds = {BvhBuild::Patch};
  opt.policies = {ConePolicy::Provot};
  opt.optimal_every = 0;
  run_sequence(seq, opt);
  const auto first = read_step_rows(opt.out / "runs" / seq.name / "patch.csv");
  EXPECT_EQ(first.size(), std::size_t(seq.steps()) * 4);
  opt.policies = {ConePolicy::Provot, ConePolicy::Exact};
  run_sequence(seq, opt);
  const auto second = read_step_rows(opt.out / "runs" / seq.name / "patch.csv");
  EXPECT_EQ(second.size(), std::size_t(seq.steps()) * 7);
  // The rows of the first run are kept as they were (not recomputed).
  for (const auto& r : first) {
    const auto it = std::find_if(second.begin(), second.end(), [&](const StepRow& s) {
      return s.step == r.step && s.culling == r.culling && s.policy == r.policy;
    });
    ASSERT_NE(it, second.end());
    EXPECT_EQ(it->ms_refit, r.ms_refit);
  }
  // OPTIMAL is measured for the spread angles only, never as a detection policy.
  EXPECT_THROW((void)parse_policy("optimal", "--policies"), InputError);
  EXPECT_EQ(parse_policy("PROPOSED", "--policies"), ConePolicy::Proposed);
  fs::remove_all(opt.out);
}

TEST(Experiment, LoadsFrameFolders) {
  const Sequence seq = folding_sheet(4, 2);
  const fs::path dir = temp_dir("frames");
  for (int k = 0; k <= seq.steps(); ++k) {
    TriangleMesh m;
    m.faces = seq.faces;
    for (Eigen::Index i = 0; i < seq.frames[k].rows(); ++i)
      m.vertices.push_back(seq.frames[k].row(i).transpose());
    // Numbered at the end, out of lexicographic order (9 < 10).
    write_obj(dir / ("f" + std::to_string(9 + k) + ".obj"), m);
  }
  const Sequence back = load_frame_folder(dir);
  ASSERT_EQ(back.steps(), seq.steps());
  for (int k = 0; k <= seq.steps(); ++k)
    EXPECT_EQ(back.frames[k], seq.frames[k]) << k;
  EXPECT_EQ(load_frame_folder(dir, 2).steps(), 1);
  fs::remove(dir / "f10.obj");
  TriangleMesh other;
  other.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  other.faces = {{0, 1, 2}};
  write_obj(dir / "f10.obj", other);
  EXPECT_THROW((void)load_frame_folder(dir), InputError);
  EXPECT_THROW((void)load_frame_folder(dir / "nothing"), InputError);
  fs::remove_all(dir);
}

}  // namespace
