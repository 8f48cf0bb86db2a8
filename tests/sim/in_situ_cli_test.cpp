// `clothcd experiment --in-situ`: on a small swinging sheet, the report and the CSV hold every
// setting's frames, the counts relate as the culling says (no culling culls nothing and tests the
// most pairs; every setting runs the same full passes), and bad input writes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "../reliability/cli_runner.hpp"

namespace clothcd {
namespace {

using test::CliScratch;

const char* kScene = R"({"name": "swing", "frames": 10, "frame_dt": 0.04,
 "cloth": {"grid": {"origin": [-0.3, 0.22, -0.3], "u": [0.6, 0, 0], "v": [0, 0, 0.6],
                    "resolution": [16, 16]}},
 "body": {"type": "sphere", "center": [0, 0, 0], "radius": 0.2, "subdivisions": 2},
 "collisions": {"self": true, "body": true, "thickness": 0.002},
 "pins": [{"grid_edge": "u0"}]})";

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');)
    cells.push_back(c);
  return cells;
}

TEST(InSitu, ReportsEverySettingOnIdenticalFrames) {
  CliScratch dir;
  dir.write("s.json", kScene);
  const auto r = dir.run("experiment --in-situ s.json --frames 3 --threads 1 --out res");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string md = CliScratch::slurp(dir / "res/in_situ.md");
  for (const char* want :
       {"clothcd experiment --in-situ s.json --frames 3 --threads 1",
        "- commit: ", "- machine: ", "load average", "## swing", "| PROVOT |", "| PROPOSED |",
        "| EXACT |", "| none |", "0.75", "0.82", "| cone PROVOT |", "| cone PROPOSED |"}) {
    EXPECT_NE(md.find(want), std::string::npos) << want << "\n" << md;
  }
  std::stringstream csv(CliScratch::slurp(dir / "res/in_situ.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const std::vector<std::string> head = split(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < head.size(); ++i)
    col[head[i]] = i;
  for (const char* c : {"setting", "frame", "self_ccd_calls", "triangle_pairs", "nodes_culled"})
    ASSERT_TRUE(col.contains(c)) << c;
  // frame -> setting -> cells
  std::map<std::string, std::map<std::string, std::vector<std::string>>> rows;
  while (std::getline(csv, line))
    rows[split(line)[col["frame"]]][split(line)[col["setting"]]] = split(line);
  ASSERT_EQ(rows.size(), 3u);
  long long pairs_none = 0, pairs_sound = 0, culled = 0, cone_culled = 0;
  for (const auto& [frame, by] : rows) {
    ASSERT_EQ(by.size(), 6u) << "frame " << frame;
    const auto& none = by.at("none");
    EXPECT_EQ(std::stoll(none[col["nodes_culled"]]), 0);
    EXPECT_GT(std::stoll(none[col["self_ccd_calls"]]), 0);
    for (const char* s : {"PROVOT", "PROPOSED", "EXACT"}) {
      const auto& row = by.at(s);
      EXPECT_EQ(row[col["self_ccd_calls"]], none[col["self_ccd_calls"]]) << s << " " << frame;
      EXPECT_LE(std::stoll(row[col["triangle_pairs"]]), std::stoll(none[col["triangle_pairs"]]))
          << s << " " << frame;
      pairs_sound += std::stoll(row[col["triangle_pairs"]]);
      culled += std::stoll(row[col["nodes_culled"]]);
    }
    pairs_none += 3 * std::stoll(none[col["triangle_pairs"]]);
    // The paper's rule, counted aside on the same full passes.
    for (const char* s : {"cone PROVOT", "cone PROPOSED"}) {
      const auto& row = by.at(s);
      EXPECT_EQ(row[col["self_ccd_calls"]], none[col["self_ccd_calls"]]) << s << " " << frame;
      EXPECT_LE(std::stoll(row[col["triangle_pairs"]]), std::stoll(none[col["triangle_pairs"]]))
          << s << " " << frame;
      cone_culled += std::stoll(row[col["nodes_culled"]]);
    }
  }
  EXPECT_GT(culled, 0);
  EXPECT_GT(cone_culled, 0);
  EXPECT_LT(pairs_sound, pairs_none);

  // The comparison with none, recomputed from the CSV (its seconds have 6 decimals): per
  // substep, the setting's refit + traversal and narrow + proximity, against none's.
  struct Sums {
    double substeps = 0, tests = 0, rest = 0;
  };
  std::map<std::string, Sums> sum;
  for (const auto& [frame, by] : rows) {
    for (const auto& [setting, cells] : by) {
      Sums& t = sum[setting];
      // A named reference: clang before 16 cannot capture a structured binding.
      const auto& row = cells;
      const auto at = [&](const char* c) { return std::stod(row[col[c]]); };
      t.substeps += at("substeps");
      t.tests += 1e3 * (at("refit_s") + at("traversal_s"));
      t.rest += 1e3 * (at("narrow_s") + at("proximity_s"));
    }
  }
  const std::size_t against = md.find("Against `none`, per substep");
  ASSERT_NE(against, std::string::npos) << md;
  std::stringstream section(md.substr(against));
  ASSERT_TRUE(sum.contains("none"));
  const Sums& n = sum.at("none");
  const double n_tests = n.tests / n.substeps, n_rest = n.rest / n.substeps;
  int checked = 0;
  while (std::getline(section, line)) {
    // "| setting | total | vs none | cost | saved | vs none if free |"
    std::vector<std::string> cell;
    std::stringstream cells(line);
    for (std::string c; std::getline(cells, c, '|');)
      cell.push_back(c.size() > 2 ? c.substr(1, c.size() - 2) : c);
    if (cell.size() != 7 || !sum.contains(cell[1])) continue;
    const Sums& t = sum.at(cell[1]);
    const double tests = t.tests / t.substeps, rest = t.rest / t.substeps;
    const double want[5] = {tests + rest, (tests + rest) / (n_tests + n_rest), tests - n_tests,
                            n_rest - rest, (n_tests + rest) / (n_tests + n_rest)};
    for (int k = 0; k < 5; ++k) {
      EXPECT_NEAR(std::stod(cell[2 + k]), want[k], 2e-3 + 1e-2 * std::abs(want[k]))
          << cell[1] << " column " << k << "\n"
          << line;
    }
    ++checked;
  }
  EXPECT_EQ(checked, 4);  // none, PROVOT, PROPOSED, EXACT
}

TEST(InSitu, BadInputWritesNothing) {
  CliScratch dir;
  const auto missing = dir.run("experiment --in-situ nope.json --frames 2 --out res");
  EXPECT_NE(missing.code, 0);
  EXPECT_NE(missing.err.find("nope.json"), std::string::npos) << missing.err;
  // Without collisions there is nothing to compare: an error naming the file.
  dir.write("plain.json", R"({"name": "plain", "frames": 2,
    "cloth": {"grid": {"resolution": [4, 4]}}, "pins": [{"grid_edge": "u0"}]})");
  const auto plain = dir.run("experiment --in-situ plain.json --frames 2 --out res");
  EXPECT_NE(plain.code, 0);
  EXPECT_NE(plain.err.find("plain.json"), std::string::npos) << plain.err;
  EXPECT_EQ(dir.files(), std::vector<std::string>{"plain.json"});
  // SCENE@N needs a positive frame count.
  dir.write("s.json", kScene);
  for (const char* bad : {"s.json@", "s.json@0", "s.json@2x"}) {
    const auto r = dir.run(std::string("experiment --in-situ ") + bad + " --frames 2 --out res");
    EXPECT_NE(r.code, 0) << bad;
    EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
  }
  EXPECT_EQ(dir.files(), (std::vector<std::string>{"plain.json", "s.json"}));
}

// SCENE@N runs at most N frames of that scene (and never more than --frames).
TEST(InSitu, SceneFrameCaps) {
  CliScratch dir;
  dir.write("s.json", kScene);
  const auto r = dir.run("experiment --in-situ s.json@1 s.json@5 --frames 2 --threads 1 --out res");
  ASSERT_EQ(r.code, 0) << r.err;
  std::stringstream csv(CliScratch::slurp(dir / "res/in_situ.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  int rows = 0;
  while (std::getline(csv, line))
    ++rows;
  EXPECT_EQ(rows, 6 * (1 + 2));  // four settings and two counted aside, 1 + 2 frames
  const std::string md = CliScratch::slurp(dir / "res/in_situ.md");
  EXPECT_NE(md.find("- scenes: 2 of 2 done"), std::string::npos) << md;
}

}  // namespace
}  // namespace clothcd
