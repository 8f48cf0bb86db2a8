// Atomic output, state round trip, and resume that matches a straight run bitwise.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "clothcd/core/error.hpp"
#include "clothcd/sim/frame_io.hpp"
#include "hash.hpp"
#include "sim/scene_json.hpp"
#include "support/files.hpp"

namespace clothcd::sim {
namespace {

namespace fs = std::filesystem;

Scene test_scene() {
  return parse_scene(nlohmann::json::parse(R"({
    "name": "resume-test",
    "frames": 5,
    "cloth": {"grid": {"origin": [0, 1, 0], "u": [0.3, 0, 0], "v": [0, 0, 0.3], "resolution": [12, 12]}},
    "pins": [{"vertices": [0, 12]}],
    "body": {"type": "sphere", "center": [0.15, 0.5, 0.15], "radius": 0.1, "velocity": [0, 1.5, 0]}
  })"),
                     "resume-test.json");
}

using clothcd::test::slurp;

struct TempDir {
  fs::path path =
      fs::temp_directory_path() / ("clothcd_sim_" + std::to_string(::getpid()) + "_" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  TempDir() { fs::remove_all(path); }
  ~TempDir() { fs::remove_all(path); }
};

TEST(FrameIo, StateRoundTripIsExact) {
  TempDir dir;
  fs::create_directories(dir.path);
  Simulation sim(test_scene());
  sim.advance_frame();
  write_state_atomic(dir.path / "s.bin", sim.state(), 1);
  int frame = -1;
  const ClothState back = read_state(dir.path / "s.bin", sim.model().num_vertices(), frame);
  EXPECT_EQ(frame, 1);
  EXPECT_EQ(test::hash_positions(back.x), test::hash_positions(sim.state().x));
  EXPECT_EQ(test::hash_positions(back.v), test::hash_positions(sim.state().v));
  EXPECT_EQ(test::hash_positions(back.dv), test::hash_positions(sim.state().dv));
  EXPECT_EQ(back.time, sim.state().time);
  EXPECT_THROW((void)read_state(dir.path / "s.bin", 3, frame), InputError);

  // A NaN velocity in the file is rejected, naming the vertex.
  ClothState bad = sim.state();
  bad.v[5].y() = std::numeric_limits<double>::quiet_NaN();
  write_state_atomic(dir.path / "nan.bin", bad, 1);
  try {
    (void)read_state(dir.path / "nan.bin", sim.model().num_vertices(), frame);
    ADD_FAILURE() << "NaN state accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("velocity of vertex 5 is not finite"), std::string::npos)
        << e.what();
  }
}

// The lock is flock(2) on a file of the folder: a second holder, even in the same process (another
// open file description), is refused and names the holder, and the run refuses with it.
TEST(FrameIo, OutputFolderTakesOneRunAtATime) {
  TempDir dir;
  const fs::path out = dir.path / "out";
  {
    const OutputLock first(out);
    EXPECT_TRUE(fs::is_directory(out));
    try {
      const OutputLock second(out);
      ADD_FAILURE() << "a second lock on the folder was granted";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("in use by another run"), std::string::npos) << msg;
      EXPECT_NE(msg.find("process " + std::to_string(::getpid())), std::string::npos) << msg;
      EXPECT_NE(msg.find((out / ".lock").string()), std::string::npos) << msg;
    }
    Simulation sim(test_scene());
    RunOptions opt;
    opt.out = out;
    EXPECT_THROW((void)run_simulation(sim, opt), std::runtime_error);
    opt.lock = &first;
    opt.frames = 1;
    EXPECT_EQ(run_simulation(sim, opt).size(), 1u);
  }
  // Released: the next run may take it, and the folder with its frames stays.
  EXPECT_NO_THROW(OutputLock again(out));
  EXPECT_TRUE(fs::exists(out / "frame_0001.obj"));
  // A folder the lock created and nothing was written to is removed again.
  { const OutputLock unused(dir.path / "unused"); }
  EXPECT_FALSE(fs::exists(dir.path / "unused"));
}

TEST(FrameIo, ResumeMatchesStraightRunBitwise) {
  TempDir dir;
  const fs::path straight = dir.path / "straight", resumed = dir.path / "resumed";
  {
    Simulation sim(test_scene());
    RunOptions opt;
    opt.out = straight;
    const auto frames = run_simulation(sim, opt);
    ASSERT_EQ(frames.size(), 5u);
    for (const auto& f : frames)
      EXPECT_TRUE(f.finite);
  }
  {
    Simulation sim(test_scene());
    RunOptions opt;
    opt.out = resumed;
    opt.frames = 3;
    EXPECT_EQ(run_simulation(sim, opt).size(), 3u);
  }
  {
    Simulation sim(test_scene());  // a fresh process would start like this
    RunOptions opt;
    opt.out = resumed;
    opt.resume = true;
    const auto frames = run_simulation(sim, opt);
    ASSERT_EQ(frames.size(), 2u);
    EXPECT_EQ(frames.front().frame, 4);
  }
  for (int k = 0; k <= 5; ++k) {
    const std::string name = "frame_000" + std::to_string(k) + ".obj";
    EXPECT_EQ(slurp(straight / name), slurp(resumed / name)) << name;
  }
  EXPECT_EQ(slurp(straight / "state_0005.bin"), slurp(resumed / "state_0005.bin"));
  EXPECT_FALSE(fs::exists(resumed / "state_0003.bin"));  // only the last state is kept
  const auto manifest = nlohmann::json::parse(slurp(resumed / "manifest.json"));
  EXPECT_EQ(manifest["complete_frames"], 5);
  ASSERT_EQ(manifest["frames"].size(), 5u);
  for (int k = 0; k < 5; ++k)
    EXPECT_EQ(manifest["frames"][k]["frame"], k + 1);
  // The header records the solver settings the frames were made with.
  const Scene scene = test_scene();
  EXPECT_EQ(manifest["solver"]["max_halvings"], scene.solver.max_halvings);
  EXPECT_EQ(manifest["solver"]["halve_unresolved"], scene.solver.halve_unresolved);
  EXPECT_EQ(manifest["solver"]["pcg_tolerance"], scene.solver.pcg_tolerance);
  EXPECT_EQ(manifest["solver"]["release_tolerance"], scene.solver.release_tolerance);
  EXPECT_EQ(manifest["solver"]["fast_pcg_tolerance"], scene.solver.fast_pcg_tolerance);
  EXPECT_EQ(manifest["solver"]["coarse_aggregate"], scene.solver.coarse_aggregate);
  // Resuming a finished run does nothing.
  Simulation sim(test_scene());
  RunOptions opt;
  opt.out = resumed;
  opt.resume = true;
  EXPECT_TRUE(run_simulation(sim, opt).empty());
}

// Runs test_scene() into `out` with the given options (a fresh process would start like this).
std::vector<FrameStats> run_into(const fs::path& out, int keep_states, bool resume,
                                 int resume_at = -1, int frames = -1) {
  Simulation sim(test_scene());
  RunOptions opt;
  opt.out = out;
  opt.keep_states = keep_states;
  opt.resume = resume;
  opt.resume_at = resume_at;
  opt.frames = frames;
  return run_simulation(sim, opt);
}

TEST(FrameIo, ResumeAtAKeptStateReplaysTheLaterFramesBitwise) {
  TempDir dir;
  const fs::path straight = dir.path / "straight", kept = dir.path / "kept";
  ASSERT_EQ(run_into(straight, 0, false).size(), 5u);
  ASSERT_EQ(run_into(kept, 2, false).size(), 5u);
  for (int k = 0; k <= 5; ++k) {
    // Frames 0, 2 and 4 are kept, and the last one.
    EXPECT_EQ(fs::exists(kept / ("state_000" + std::to_string(k) + ".bin")), k % 2 == 0 || k == 5)
        << k;
  }
  // Neither a frame past the run nor one whose state was not kept can be resumed at; the
  // folder is left as it was.
  for (const int at : {6, 3}) {
    EXPECT_THROW((void)run_into(kept, 0, true, at), InputError) << at;
    EXPECT_TRUE(fs::exists(kept / "state_0005.bin"));
  }
  EXPECT_THROW((void)run_into(dir.path / "nothing", 0, true, 0), InputError);
  EXPECT_FALSE(fs::exists(dir.path / "nothing"));  // no partial output
  // Replaying from frame 2 and stopping at 3: the manifest ends at frame 3 and the later files
  // are gone.
  const auto frames = run_into(kept, 0, true, 2, 3);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames.front().frame, 3);
  const auto manifest = nlohmann::json::parse(slurp(kept / "manifest.json"));
  EXPECT_EQ(manifest["complete_frames"], 3);
  EXPECT_EQ(manifest["frames"].size(), 3u);
  for (const char* gone : {"frame_0004.obj", "frame_0005.obj", "state_0004.bin", "state_0005.bin"})
    EXPECT_FALSE(fs::exists(kept / gone)) << gone;
  EXPECT_TRUE(fs::exists(kept / "state_0002.bin"));  // the state the replay started from stays
  // Resumed to the end, the frames are those of the straight run.
  ASSERT_EQ(run_into(kept, 0, true).size(), 2u);
  for (int k = 0; k <= 5; ++k) {
    const std::string name = "frame_000" + std::to_string(k) + ".obj";
    EXPECT_EQ(slurp(straight / name), slurp(kept / name)) << name;
  }
  EXPECT_EQ(slurp(straight / "state_0005.bin"), slurp(kept / "state_0005.bin"));
}

TEST(FrameIo, PlyOutputHasHeaderAndBinaryBody) {
  TempDir dir;
  fs::create_directories(dir.path);
  const std::vector<Vec3> x{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  write_mesh_atomic(dir.path / "m.ply", x, {{0, 1, 2}}, "ply");
  const std::string s = slurp(dir.path / "m.ply");
  const auto end = s.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  EXPECT_EQ(s.size() - end - 11, 3u * 12u + 13u);
}

}  // namespace
}  // namespace clothcd::sim
