// The scripts that read `clothcd simulate` folders (stitch_gaps.py, frame_strain.py,
// sim_summary.py) on hand-made folders whose figures are known by construction (stitch gaps of
// 1, 2 and 3 mm; a triangle stretched 20%; two frames' times and counts), and their errors for
// bad input: each names the file and what was expected, exits non-zero and prints no
// table.
// Needs /usr/bin/python3 (the scripts use the standard library only) and skips without it.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace run_scripts_test {

namespace fs = std::filesystem;

struct ScriptRun {
  int status = 0;
  std::string output;
};

// `script` of scripts/ with `args` (quoted by the caller where needed), stderr included.
ScriptRun run_script(const std::string& script, const std::string& args) {
  const std::string cmd =
      "/usr/bin/python3 " CLOTHCD_SOURCE_DIR "/scripts/" + script + " " + args + " 2>&1";
  ScriptRun r;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, "popen failed"};
  char buf[512];
  while (fgets(buf, sizeof buf, p) != nullptr)
    r.output += buf;
  r.status = pclose(p);
  return r;
}

void write(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
}

// Vertices 3, 4, 5 lie 1, 2 and 3 mm off the points of edge 0-1 they are sewn to.
constexpr const char* kFrame =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.5 0.001 0\nv 0.25 0.002 0\nv 0.75 0 0.003\nf 1 2 3\n";

fs::path make_run(const fs::path& dir, const std::string& stitch_lines) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  write(dir / "pattern.obj", std::string(kFrame) + stitch_lines);
  write(dir / "scene.json", "{\"cloth\": {\"obj\": \"" + (dir / "pattern.obj").string() +
                                "\", \"pattern\": \"" + (dir / "pattern.obj").string() +
                                "\", \"stitches\": \"pattern\"}}");
  write(dir / "manifest.json", "{\"scene\": \"tiny\", \"scene_file\": \"" +
                                   (dir / "scene.json").string() +
                                   "\", \"complete_frames\": 1, \"mesh_format\": \"obj\"}");
  write(dir / "frame_0001.obj", kFrame);
  return dir;
}

ScriptRun stitch_gaps(const fs::path& folder) {
  return run_script("stitch_gaps.py", "'" + folder.string() + "'");
}

fs::path scratch(const std::string& name) {
  return fs::temp_directory_path() /
         (name + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
}

TEST(StitchGapsScript, GapsOfAHandMadeRun) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "/usr/bin/python3 not found";
  const fs::path base = scratch("clothcd_stitch_gaps_");
  const fs::path good =
      make_run(base / "good", "stitch 3 0 1 0.5\nstitch 4 0 1 0.25\nstitch 5 0 1 0.75\n");
  const ScriptRun r = stitch_gaps(good);
  EXPECT_EQ(r.status, 0) << r.output;
  // Nearest-rank median and p90 of {1, 2, 3} mm: 2 and 3.
  EXPECT_NE(r.output.find("| tiny | 1-1 | 3 | 2.00-2.00 | 3.00-3.00 | 3.00-3.00 | "
                          "2.00 / 3.00 / 3.00 |"),
            std::string::npos)
      << r.output;

  const fs::path bad = make_run(base / "bad", "stitch 3 0 1 0.5\nstitch 4 0 1\n");
  const ScriptRun b = stitch_gaps(bad);
  EXPECT_NE(b.status, 0) << b.output;
  EXPECT_NE(b.output.find("pattern.obj:9: expected 'stitch a b c r'"), std::string::npos)
      << b.output;
  EXPECT_EQ(b.output.find("| tiny |"), std::string::npos) << "no partial output: " << b.output;

  const fs::path gone =
      make_run(base / "gone", "stitch 3 0 1 0.5\nstitch 4 0 1 0.25\nstitch 5 0 1 0.75\n");
  fs::remove(gone / "frame_0001.obj");
  const ScriptRun g = stitch_gaps(gone);
  EXPECT_NE(g.status, 0) << g.output;
  EXPECT_NE(g.output.find("frame_0001.obj: missing"), std::string::npos) << g.output;

  // A pattern file the scene names but the disk lacks: refused by name, not a traceback.
  const fs::path lost =
      make_run(base / "lost", "stitch 3 0 1 0.5\nstitch 4 0 1 0.25\nstitch 5 0 1 0.75\n");
  fs::remove(lost / "pattern.obj");
  const ScriptRun l = stitch_gaps(lost);
  EXPECT_NE(l.status, 0) << l.output;
  EXPECT_NE(l.output.find("cloth.pattern names " + (lost / "pattern.obj").string() +
                          ", which is missing"),
            std::string::npos)
      << l.output;
  EXPECT_EQ(l.output.find("Traceback"), std::string::npos) << l.output;

  const ScriptRun none = stitch_gaps(base / "missing");
  EXPECT_NE(none.status, 0) << none.output;
  EXPECT_NE(none.output.find("no manifest.json"), std::string::npos) << none.output;
  fs::remove_all(base);
}

// Two separate triangles, the first stretched 20% along x in frame 1, the second at rest.
constexpr const char* kRest =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 2 1 0\nf 1 2 3\nf 4 5 6\n";
constexpr const char* kStretched =
    "v 0 0 0\nv 1.2 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 2 1 0\nf 1 2 3\nf 4 5 6\n";

fs::path make_strain_run(const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  write(dir / "initial.obj", kRest);
  write(dir / "scene.json", "{\"cloth\": {\"obj\": \"" + (dir / "initial.obj").string() +
                                "\", \"rest\": \"initial\"}}");
  // The manifest's own per-frame figures (--manifest) differ from the frame's on purpose.
  write(dir / "manifest.json",
        "{\"scene\": \"tiny\", \"scene_file\": \"" + (dir / "scene.json").string() +
            "\", \"complete_frames\": 1, \"mesh_format\": \"obj\", \"frames\": [{\"frame\": 1, "
            "\"strain\": {\"median\": 0.001, \"p90\": 0.01, \"p99\": 0.04, \"p999\": 0.08, "
            "\"max\": 0.15, \"over_10\": 0.002}}]}");
  write(dir / "frame_0001.obj", kStretched);
  return dir;
}

ScriptRun frame_strain(const std::string& options, const fs::path& folder) {
  return run_script("frame_strain.py", options + " '" + folder.string() + "'");
}

TEST(FrameStrainScript, StrainOfAHandMadeRun) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "/usr/bin/python3 not found";
  const fs::path base = scratch("clothcd_frame_strain_");
  const fs::path good = make_strain_run(base / "good");
  // Strains {0, 0.2}: nearest-rank median 0, p90 and above 20%, half the triangles over 10%; over
  // 10% / 10% / 30%: 1 / 1 / 0 frames.
  const ScriptRun r = frame_strain("--over 0.1,0.1,0.3", good);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("| tiny | 1-1 | 0.0-0.0% | 20.0-20.0% | 20.0-20.0% | 20.0-20.0% | "
                          "20.0-20.0% | 50.0-50.0% | 1 / 1 / 0 |"),
            std::string::npos)
      << r.output;
  const ScriptRun m = frame_strain("--manifest", good);
  EXPECT_EQ(m.status, 0) << m.output;
  EXPECT_NE(m.output.find("| tiny | 1-1 | 0.1-0.1% | 1.0-1.0% | 4.0-4.0% | 8.0-8.0% | "
                          "15.0-15.0% | 0.2-0.2% |"),
            std::string::npos)
      << m.output;

  // Bad input: the file and what was expected, a non-zero exit, no table.
  const auto refused = [](const ScriptRun& run, const std::string& message) {
    EXPECT_NE(run.status, 0) << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << run.output;
    EXPECT_EQ(run.output.find("| run |"), std::string::npos) << "no partial output: " << run.output;
    EXPECT_EQ(run.output.find("Traceback"), std::string::npos) << run.output;
  };
  const fs::path lost = make_strain_run(base / "lost");
  fs::remove(lost / "initial.obj");
  refused(frame_strain("", good.string() + "' '" + lost.string()),
          "cloth.obj names " + (lost / "initial.obj").string() + ", which is missing");
  const fs::path torn = make_strain_run(base / "torn");
  write(torn / "frame_0001.obj", "v 0 0 0\nv 1.2 0\n");
  refused(frame_strain("", torn), "frame_0001.obj:2: expected 'v x y z'");
  const fs::path gone = make_strain_run(base / "gone");
  fs::remove(gone / "frame_0001.obj");
  refused(frame_strain("", gone), "frame_0001.obj: missing, though the manifest counts 1");
  refused(frame_strain("", base / "missing"), "no manifest.json");
  refused(frame_strain("--over 0.05", good), "expected three fractions P99,P999,MAX");
  fs::remove_all(base);
}

TEST(SimSummaryScript, RowOfAHandMadeRun) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "/usr/bin/python3 not found";
  const fs::path base = scratch("clothcd_sim_summary_");
  fs::create_directories(base / "good");
  fs::create_directories(base / "bad");
  write(base / "good" / "manifest.json",
        "{\"scene\": \"tiny\", \"complete_frames\": 2, \"initial_self_intersections\": 0, "
        "\"initial_body_intersections\": 0, \"frames\": ["
        "{\"frame\": 1, \"seconds\": 2, \"collision_seconds\": 1, \"substeps\": 4, "
        "\"self_intersections\": 0, \"body_intersections\": 0, \"unresolved_ccd_hits\": 0}, "
        "{\"frame\": 2, \"seconds\": 4, \"collision_seconds\": 1, \"substeps\": 6, "
        "\"self_intersections\": 2, \"body_intersections\": 1, \"unresolved_ccd_hits\": 3}]}");
  write(base / "bad" / "manifest.json", "{\"scene\": \"tiny\", \"complete_frames\": 2}");
  const auto summary = [&](const std::string& folders) {
    return run_script("sim_summary.py", folders);
  };
  // Seconds 2 and 4 (median and mean 3), collisions 2 of 6 s, the worst and last frame 2.
  const ScriptRun r = summary("'" + (base / "good").string() + "'");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("| tiny | 2 | 3.0 / 3.0 | 33% | 4-6 | 0 / 0 | 2 / 1 (frame 2) | 2 / 1 | "
                          "1 | 3 in 1 frames |"),
            std::string::npos)
      << r.output;
  const ScriptRun b =
      summary("'" + (base / "good").string() + "' '" + (base / "bad").string() + "'");
  EXPECT_NE(b.status, 0) << b.output;
  EXPECT_NE(b.output.find("bad: cannot read manifest.json: no 'frames' in it"), std::string::npos)
      << b.output;
  EXPECT_EQ(b.output.find("| scene |"), std::string::npos) << "no partial output: " << b.output;
  // A folder that fails only in the strain table, before one that fails in the first: the
  // message names the first with its own error, not the other's.
  fs::create_directories(base / "late");
  write(base / "late" / "manifest.json",
        "{\"scene\": \"tiny\", \"complete_frames\": 1, \"initial_self_intersections\": 0, "
        "\"initial_body_intersections\": 0, \"frames\": ["
        "{\"frame\": 1, \"seconds\": 2, \"collision_seconds\": 1, \"substeps\": 4, "
        "\"self_intersections\": 0, \"body_intersections\": 0, \"unresolved_ccd_hits\": 0, "
        "\"strain\": {\"median\": 0.01, \"p99\": 0.02, \"p999\": 0.03, \"max\": 0.04}}]}");
  const ScriptRun l =
      summary("'" + (base / "late").string() + "' '" + (base / "bad").string() + "'");
  EXPECT_NE(l.status, 0) << l.output;
  EXPECT_NE(l.output.find("late: cannot read manifest.json: no 'max_site' in it"),
            std::string::npos)
      << l.output;
  EXPECT_EQ(l.output.find("| scene |"), std::string::npos) << "no partial output: " << l.output;
  fs::remove_all(base);
}

}  // namespace run_scripts_test
