// Regression tests for the simulator's inputs (OBJ for cloth, pattern and body frames, read with
// the mesh module's reader; scene JSON), for the input classes the fuzz targets fuzz_obj and
// fuzz_scene check.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/sim/scene.hpp"

namespace clothcd {
namespace {

using test::CliScratch;

// Expects an InputError whose message contains every part.
template <class F>
void expect_input_error(F&& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    for (const auto& p : parts) {
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what() << " lacks " << p;
    }
  }
}

// Found by fuzz_sim_obj, when the simulator had its own OBJ reader: std::from_chars reads
// "nan"/"inf", so they reached the solver.
TEST(SimObjInput, RejectsNonFiniteCoordinates) {
  CliScratch dir;
  for (const char* bad : {"nan", "inf", "-inf", "NaN"}) {
    const auto p =
        dir.write("c.obj", std::string("v 0 0 0\nv 1 ") + bad + " 0\nv 0 1 0\nf 1 2 3\n");
    expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"c.obj:2:", "not finite"});
    expect_input_error([&] { (void)read_obj_vertices(p); }, {"c.obj:2:", "not finite"});
  }
  const auto p = dir.write("t.obj", "v 0 0 0\nvt nan 0\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"t.obj:2:", "not finite"});
  const auto s = dir.write("s.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nstitch 0 1 2 inf\n");
  expect_input_error([&] { (void)read_obj_with_stitches(s); }, {"s.obj:4:", "stitch weight"});
}

// A stitch index of 2^32 + 1 was once narrowed to vertex 1 and accepted.
TEST(SimObjInput, RejectsStitchIndexPastInt) {
  CliScratch dir;
  const auto p = dir.write("s.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nstitch 4294967297 0 2 0.5\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"s.obj:4:", "4294967297"});
  // Forward references stay allowed: the count is checked once the file is read.
  const auto q = dir.write("f.obj", "stitch 2 0 1 0.5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(read_obj_with_stitches(q).stitches.size(), 1u);
}

TEST(SimObjInput, RejectsIndicesOutOfRangeAndShortFaces) {
  CliScratch dir;
  auto p = dir.write("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"a.obj:4:", "out of range"});
  p = dir.write("b.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"b.obj:3:", "2 corners"});
  p = dir.write("c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/9 2 3\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); },
                     {"c.obj:4:", "texture index 9 is out of range"});
  p = dir.write("d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/-2 2 3\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); },
                     {"d.obj:5:", "relative texture index -2"});
}

TEST(SceneInput, RejectsHugeGridResolutionWithoutOverflow) {
  CliScratch dir;
  // nu * nv overflows 64 bits; must be an InputError (UBSan would flag signed overflow).
  const auto p = dir.write(
      "s.json", R"({"name": "n", "cloth": {"grid": {"resolution": [4294967297, 4294967297]}}})");
  expect_input_error([&] { (void)sim::load_scene(p); }, {"s.json", "resolution"});
  const auto q =
      dir.write("t.json", R"({"name": "n", "cloth": {"grid": {"resolution": [3000, 3000]}}})");
  expect_input_error([&] { (void)sim::load_scene(q); }, {"t.json", "resolution"});
}

}  // namespace
}  // namespace clothcd
