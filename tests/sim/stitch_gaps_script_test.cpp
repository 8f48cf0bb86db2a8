// scripts/stitch_gaps.py on a hand-made run folder: three stitches whose gaps are 1, 2 and 3 mm
// by construction, and the errors for a malformed stitch line, a missing frame file and a folder
// without a manifest.
// Needs /usr/bin/python3 (the script uses the standard library only) and skips without it.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace stitch_gaps_test {

namespace fs = std::filesystem;

struct ScriptRun {
  int status = 0;
  std::string output;
};

ScriptRun run_script(const fs::path& folder) {
  const std::string cmd = "/usr/bin/python3 " CLOTHCD_SOURCE_DIR "/scripts/stitch_gaps.py '" +
                          folder.string() + "' 2>&1";
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

TEST(StitchGapsScript, GapsOfAHandMadeRun) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "/usr/bin/python3 not found";
  const fs::path base =
      fs::temp_directory_path() /
      ("clothcd_stitch_gaps_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  const fs::path good =
      make_run(base / "good", "stitch 3 0 1 0.5\nstitch 4 0 1 0.25\nstitch 5 0 1 0.75\n");
  const ScriptRun r = run_script(good);
  EXPECT_EQ(r.status, 0) << r.output;
  // Nearest-rank median and p90 of {1, 2, 3} mm: 2 and 3.
  EXPECT_NE(r.output.find("| tiny | 1-1 | 3 | 2.00-2.00 | 3.00-3.00 | 3.00-3.00 | "
                          "2.00 / 3.00 / 3.00 |"),
            std::string::npos)
      << r.output;

  const fs::path bad = make_run(base / "bad", "stitch 3 0 1 0.5\nstitch 4 0 1\n");
  const ScriptRun b = run_script(bad);
  EXPECT_NE(b.status, 0) << b.output;
  EXPECT_NE(b.output.find("pattern.obj:9: expected 'stitch a b c r'"), std::string::npos)
      << b.output;
  EXPECT_EQ(b.output.find("| tiny |"), std::string::npos) << "no partial output: " << b.output;

  const fs::path gone =
      make_run(base / "gone", "stitch 3 0 1 0.5\nstitch 4 0 1 0.25\nstitch 5 0 1 0.75\n");
  fs::remove(gone / "frame_0001.obj");
  const ScriptRun g = run_script(gone);
  EXPECT_NE(g.status, 0) << g.output;
  EXPECT_NE(g.output.find("frame_0001.obj: missing"), std::string::npos) << g.output;

  const ScriptRun none = run_script(base / "missing");
  EXPECT_NE(none.status, 0) << none.output;
  EXPECT_NE(none.output.find("no manifest.json"), std::string::npos) << none.output;
  fs::remove_all(base);
}

}  // namespace stitch_gaps_test
