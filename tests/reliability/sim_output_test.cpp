// `clothcd simulate` and its output folder under failure: killed at named points of the writer
// and at random moments, then resumed, it ends with the frames and manifest of an uninterrupted
// run, byte for byte; a second run on a folder in use refuses; a full disk or a read-only folder
// gives the file and the real reason and keeps the last complete frame; and the frames do not
// depend on the thread count. Runs the built `clothcd` binary (CLOTHCD_CLI).

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.hpp"

namespace clothcd {
namespace {

namespace fs = std::filesystem;
using test::CliResult;
using test::CliScratch;

// A pinned sheet falling onto a sphere, with self and body collisions: contacts and CCD hits from
// frame 2 on, about 0.1 s per frame.
const char* kScene = R"({"name": "crash", "frames": 6, "frame_dt": 0.04,
 "cloth": {"grid": {"origin": [-0.3, 0.22, -0.3], "u": [0.6, 0, 0], "v": [0, 0, 0.6],
                    "resolution": [24, 24]}},
 "body": {"type": "sphere", "center": [0, 0, 0], "radius": 0.2, "subdivisions": 2},
 "collisions": {"self": true, "body": true, "thickness": 0.002},
 "pins": [{"grid_edge": "u0"}]})";
// Smaller and without collisions, for 12 frames whose manifest outgrows the state file.
const char* kSmallScene = R"({"name": "small", "frames": 12, "frame_dt": 0.04,
 "cloth": {"grid": {"origin": [-0.3, 0.3, -0.3], "u": [0.6, 0, 0], "v": [0, 0, 0.6],
                    "resolution": [8, 8]}},
 "body": {"type": "sphere", "center": [0, 0, 0], "radius": 0.2, "subdivisions": 1},
 "pins": [{"grid_edge": "u0"}]})";
constexpr int kFrames = 6;

std::string frame_file(int k) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04d.obj", k);
  return name;
}
std::string state_file(int k) {
  char name[32];
  std::snprintf(name, sizeof name, "state_%04d.bin", k);
  return name;
}

// The manifest without its wall-clock figures, and without the self detector's figures: besides
// their times, their counts depend on the detector's history (its tree and the pairs it keeps),
// which a resumed run starts afresh.
nlohmann::json without_times(nlohmann::json j) {
  for (auto& f : j["frames"]) {
    for (const char* k : {"seconds", "collision_seconds", "intersection_seconds", "strain_seconds",
                          "self_ccd", "self_proximity", "collision_parts"})
      f.erase(k);
  }
  return j;
}

nlohmann::json read_manifest(const fs::path& dir) {
  return nlohmann::json::parse(CliScratch::slurp(dir / "manifest.json"));
}

// An uninterrupted run into `ref` that keeps every frame's state, to compare any frame with.
void reference_run(const CliScratch& dir, int frames = kFrames) {
  const auto r =
      dir.run("simulate s.json --keep-states 1 --frames " + std::to_string(frames) + " --out ref");
  ASSERT_EQ(r.code, 0) << r.err;
}

// What must hold in `out` at any moment: when there is a manifest, it parses, and every frame it
// calls complete, its state file and its per-frame figures are the reference's, byte for byte.
// Returns the complete frames (-1: no manifest yet).
int check_committed(const CliScratch& dir, const std::string& out) {
  const fs::path o = dir / out, ref = dir / "ref";
  if (!fs::exists(o / "manifest.json")) return -1;
  nlohmann::json m;
  try {
    m = read_manifest(o);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "unreadable manifest: " << e.what();
    return -1;
  }
  const int done = m.at("complete_frames").get<int>();
  EXPECT_EQ(m.at("state_file").get<std::string>(), state_file(done));
  EXPECT_EQ(CliScratch::slurp(o / state_file(done)), CliScratch::slurp(ref / state_file(done)))
      << state_file(done);
  for (int k = 0; k <= done; ++k) {
    EXPECT_EQ(CliScratch::slurp(o / frame_file(k)), CliScratch::slurp(ref / frame_file(k)))
        << frame_file(k) << " of " << done << " complete frames";
  }
  const auto ours = without_times(m)["frames"],
             theirs = without_times(read_manifest(ref))["frames"];
  EXPECT_EQ(ours.size(), static_cast<std::size_t>(done));
  for (int k = 0; k < done && k < static_cast<int>(ours.size()); ++k)
    EXPECT_EQ(ours[k], theirs[k]) << "manifest entry of frame " << k + 1;
  return done;
}

// The finished run in `out` against the reference: every frame, the last state and the manifest
// (timings aside) byte-identical; no temporary file left; nothing but the reference's files.
void check_finished(const CliScratch& dir, const std::string& out, int frames = kFrames) {
  const fs::path o = dir / out, ref = dir / "ref";
  ASSERT_EQ(check_committed(dir, out), frames);
  for (int k = 0; k <= frames; ++k)
    EXPECT_EQ(CliScratch::slurp(o / frame_file(k)), CliScratch::slurp(ref / frame_file(k))) << k;
  EXPECT_EQ(without_times(read_manifest(o)), without_times(read_manifest(ref)));
  for (const auto& e : fs::directory_iterator(o)) {
    const std::string name = e.path().filename().string();
    // A kill between a manifest's rename and the removal of the state it replaced leaves that
    // state behind: still a valid state, the reference's byte for byte.
    EXPECT_TRUE(fs::exists(ref / name)) << "unexpected file " << name;
    if (name.starts_with("state_")) {
      EXPECT_EQ(CliScratch::slurp(e.path()), CliScratch::slurp(ref / name)) << name;
    }
  }
}

std::string fault(const std::string& point) {
  return "CLOTHCD_FAULT=" + point;
}

const std::vector<std::string> kResume = {"simulate", "s.json", "--resume", "--out", "run"};

// The writer kills the run at named points: inside a frame file, between a frame's files, inside
// and around the manifest update (the commit point); each resume continues from the last commit.
TEST(SimCrash, KilledAtEveryWriteStageThenResumedMatchesStraightRun) {
  CliScratch dir;
  dir.write("s.json", kScene);
  reference_run(dir);
  // In order: each point lies ahead of where the resumed run starts, so each must be reached.
  const std::vector<std::pair<std::string, int>> points = {
      {"partial:frame_0000.obj", -1},  // inside the first file: nothing committed
      {"written:manifest.json", -1},   // the first manifest complete but not renamed
      {"partial:frame_0002.obj", 1},   // inside a frame file
      {"renamed:state_0002.bin", 1},   // frame and state written, manifest not yet
      {"partial:manifest.json", 1},    // inside the manifest update
      {"renamed:manifest.json:2", 3},  // frame 3 committed, its predecessor's state not removed
      {"written:state_0004.bin", 3},   // a state complete but not renamed
      {"renamed:frame_0006.obj", 5}};  // the last frame's mesh in place, uncommitted
  for (const auto& [point, committed] : points) {
    const CliResult r = dir.wait(dir.spawn(kResume, {fault(point)}));
    ASSERT_EQ(r.code, 128 + SIGKILL) << point << " not reached: " << r.err;
    EXPECT_EQ(check_committed(dir, "run"), committed) << "after a kill at " << point;
  }
  const CliResult r = dir.wait(dir.spawn(kResume));
  ASSERT_EQ(r.code, 0) << r.err;
  check_finished(dir, "run");
}

// SIGKILL at random moments (seeded; CLOTHCD_CRASH_SEED overrides the seed), each followed by a
// resume. A run that finishes before its kill is checked and started again from nothing, until
// there were kKills kills; then the last run is resumed to its end and checked.
TEST(SimCrash, KilledAtRandomMomentsThenResumedMatchesStraightRun) {
  constexpr int kKills = 6;
  CliScratch dir;
  dir.write("s.json", kScene);
  const auto t0 = std::chrono::steady_clock::now();
  reference_run(dir);
  const double straight =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  unsigned seed = 20240611;
  if (const char* s = std::getenv("CLOTHCD_CRASH_SEED")) seed = std::strtoul(s, nullptr, 10);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> when(0.0, 0.7 * straight);
  int kills = 0, finished = 0, last = -1;
  std::string committed;
  for (int attempt = 0; kills < kKills && attempt < 4 * kKills; ++attempt) {
    const pid_t pid = dir.spawn(kResume);
    std::this_thread::sleep_for(std::chrono::duration<double>(when(rng)));
    ::kill(pid, SIGKILL);
    const CliResult r = dir.wait(pid);
    if (r.code == 0) {  // finished before the kill
      check_finished(dir, "run");
      ++finished;
      fs::remove_all(dir / "run");
      last = -1;
      committed += " |";
      continue;
    }
    ASSERT_EQ(r.code, 128 + SIGKILL) << r.err;
    ++kills;
    const int done = check_committed(dir, "run");
    EXPECT_GE(done, last) << "a kill lost committed frames (seed " << seed << ")";
    last = done;
    committed += " " + std::to_string(done);
  }
  std::printf(
      "seed %u: %d kills, %d runs finished before their kill; complete frames after each "
      "kill (| a finished run):%s\n",
      seed, kills, finished, committed.c_str());
  EXPECT_EQ(kills, kKills) << "seed " << seed;
  const CliResult r = dir.wait(dir.spawn(kResume));
  ASSERT_EQ(r.code, 0) << r.err;
  check_finished(dir, "run");
}

// A second run, fresh or resumed, on a folder in use refuses at once and writes nothing; the first
// run (held stopped meanwhile) then finishes with the frames of a run on its own.
TEST(SimLock, SecondRunOnAFolderInUseRefuses) {
  CliScratch dir;
  dir.write("s.json", kScene);
  reference_run(dir);
  const pid_t first =
      dir.spawn({"simulate", "s.json", "--out", "run"}, {fault("stop:renamed:frame_0002.obj")});
  ASSERT_TRUE(CliScratch::wait_stopped(first));
  for (const char* args : {"simulate s.json --out run", "simulate s.json --resume --out run"}) {
    const CliResult second = dir.run(args);
    EXPECT_EQ(second.code, 1) << second.err;
    EXPECT_NE(second.err.find("in use by another run"), std::string::npos) << second.err;
    EXPECT_NE(second.err.find("process " + std::to_string(first)), std::string::npos) << second.err;
    EXPECT_NE(second.err.find("run/.lock"), std::string::npos) << second.err;
  }
  ::kill(first, SIGCONT);
  const CliResult r = dir.wait(first);
  ASSERT_EQ(r.code, 0) << r.err;
  check_finished(dir, "run");
}

// A file size limit (EFBIG, as root too) stops the run when the growing manifest passes it: the
// error names the file and the reason, the committed frames are intact, no temporary is left, and
// a resume with room to write finishes like a straight run.
TEST(SimFullDisk, FileSizeLimitKeepsTheLastCompleteFrame) {
  CliScratch dir;
  dir.write("s.json", kSmallScene);
  reference_run(dir, 12);
  const std::size_t state_bytes = fs::file_size(dir / "ref" / state_file(0));
  const std::size_t manifest_bytes = fs::file_size(dir / "ref/manifest.json");
  // In blocks of 512 bytes (sh's `ulimit -f`), a block more than the state file needs.
  const std::size_t limit_blocks = (state_bytes + 511) / 512 + 1;
  ASSERT_GT(manifest_bytes, limit_blocks * 512) << "the manifest must outgrow the limit";
  const CliResult r = dir.run("simulate s.json --frames 12 --out run",
                              "trap '' XFSZ; ulimit -f " + std::to_string(limit_blocks) + ";");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("cannot write 'run/manifest.json'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(std::strerror(EFBIG)), std::string::npos) << r.err;
  const int done = check_committed(dir, "run");
  EXPECT_GE(done, 1);
  EXPECT_LT(done, 12);
  for (const auto& e : fs::directory_iterator(dir / "run"))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  const CliResult resumed = dir.run("simulate s.json --frames 12 --resume --out run");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  check_finished(dir, "run", 12);
}

// The next tests mount a small tmpfs in a new mount namespace (unshare -rm: as root, or as a user
// where user namespaces are allowed), since neither a full disk nor a read-only folder can be
// made otherwise for root. The namespace's mounts vanish with it, so the script copies the output
// to `saved` before leaving.
bool can_mount_tmpfs(const CliScratch& dir) {
  return std::system(("cd '" + dir.dir().string() +
                      "' && mkdir -p probe && unshare -rm sh -c 'mount -t tmpfs -o size=64k "
                      "tmpfs probe' >/dev/null 2>&1")
                         .c_str()) == 0;
}

// Runs `script` (sh) in a new mount namespace with a tmpfs of `size` on `mnt`; `$CLI` is clothcd.
CliResult in_namespace(const CliScratch& dir, const std::string& size, const std::string& script) {
  dir.write("ns.sh", "set -u\nmkdir -p mnt\nmount -t tmpfs -o size=" + size +
                         " tmpfs mnt || exit 90\nCLI='" CLOTHCD_CLI "'\n" + script);
  return dir.run_shell("unshare -rm sh ns.sh");
}

// 192 KiB hold frame 0 (28 KiB in pages), a state (48 KiB), the manifest and a frame's temporaries
// for a frame or two, then a write fails for want of space.
TEST(SimFullDisk, FullTmpfsKeepsTheLastCompleteFrame) {
  CliScratch dir;
  if (!can_mount_tmpfs(dir)) GTEST_SKIP() << "cannot mount a tmpfs in a namespace (unshare -rm)";
  dir.write("s.json", kScene);
  reference_run(dir);
  const CliResult r = in_namespace(
      dir, "192k",
      "\"$CLI\" simulate s.json --out mnt/run\ncode=$?\ncp -a mnt/run saved\nexit $code\n");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("cannot write 'mnt/run/"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(std::strerror(ENOSPC)), std::string::npos) << r.err;
  const int done = check_committed(dir, "saved");
  EXPECT_GE(done, 1);
  EXPECT_LT(done, kFrames);
  for (const auto& e : fs::directory_iterator(dir / "saved"))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  const CliResult resumed = dir.run("simulate s.json --resume --out saved");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  check_finished(dir, "saved");
}

// The folder turns read-only while the run is held stopped after frame 2's mesh: writing frame 2's
// state fails with the reason; frames 0-1 stay committed; a resume on the read-only folder refuses
// at once; once writable again, a resume finishes like a straight run.
TEST(SimReadOnly, FolderTurnedReadOnlyKeepsTheLastCompleteFrame) {
  CliScratch dir;
  if (!can_mount_tmpfs(dir)) GTEST_SKIP() << "cannot mount a tmpfs in a namespace (unshare -rm)";
  dir.write("s.json", kScene);
  reference_run(dir);
  const CliResult r = in_namespace(
      dir, "4m",
      "CLOTHCD_FAULT=stop:renamed:frame_0002.obj \"$CLI\" simulate s.json --out mnt/run "
      "2>first.err &\npid=$!\n"
      "while kill -0 $pid 2>/dev/null && [ \"$(cut -d' ' -f3 /proc/$pid/stat)\" != T ]; do "
      "sleep 0.02; done\n"
      "mount -o remount,ro mnt || exit 91\nkill -CONT $pid\nwait $pid\necho $? >first.code\n"
      "\"$CLI\" simulate s.json --resume --out mnt/run\ncode=$?\n"
      "cp -a mnt/run saved\nexit $code\n");
  EXPECT_EQ(CliScratch::slurp(dir / "first.code"), "1\n");
  const std::string first = CliScratch::slurp(dir / "first.err");
  EXPECT_NE(first.find("cannot write 'mnt/run/state_0002.bin'"), std::string::npos) << first;
  EXPECT_NE(first.find(std::strerror(EROFS)), std::string::npos) << first;
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("cannot write to output folder 'mnt/run'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(std::strerror(EROFS)), std::string::npos) << r.err;
  EXPECT_EQ(check_committed(dir, "saved"), 1);
  const CliResult resumed = dir.run("simulate s.json --resume --out saved");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  check_finished(dir, "saved");
}

// Every frame, state and manifest figure the same on 1, 2 and 4 threads.
TEST(SimDeterminism, SameFramesOnOneTwoAndFourThreads) {
  CliScratch dir;
  dir.write("s.json", kScene);
  for (const char* t : {"1", "2", "4"}) {
    const auto r = dir.run(std::string("simulate s.json --threads ") + t + " --out t" + t);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  for (const char* t : {"2", "4"}) {
    const fs::path a = dir / "t1", b = dir / (std::string("t") + t);
    for (int k = 0; k <= kFrames; ++k) {
      EXPECT_EQ(CliScratch::slurp(a / frame_file(k)), CliScratch::slurp(b / frame_file(k)))
          << frame_file(k) << " on " << t << " threads";
    }
    EXPECT_EQ(CliScratch::slurp(a / state_file(kFrames)),
              CliScratch::slurp(b / state_file(kFrames)))
        << t << " threads";
    EXPECT_EQ(without_times(read_manifest(a)), without_times(read_manifest(b))) << t << " threads";
  }
}

}  // namespace
}  // namespace clothcd
