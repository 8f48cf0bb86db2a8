// Fuzzes the scene loader (JSON text -> validated Scene): InputError or a scene whose cloth is a
// valid mesh, never a crash or another exception. The scene lives in a scratch folder that also
// holds a small cloth OBJ (with texture coordinates and stitch lines) and two body frames, so
// relative paths and ${CLOTHCD_DATA} (set to that folder) reach the OBJ, pattern and frame code.
#include <stdlib.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "clothcd/core/error.hpp"
#include "clothcd/sim/scene.hpp"

namespace {

namespace fs = std::filesystem;

void write(const fs::path& p, const char* text) {
  std::ofstream(p, std::ios::binary) << text;
}

const fs::path& scratch() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("clothcd-fuzz-scene-" + std::to_string(::getpid()));
    fs::create_directories(d);
    // 2x1 quad strip: 6 vertices, 4 faces, texture coordinates equal to x/y, one stitch.
    write(d / "cloth.obj",
          "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n"
          "vt 0 0\nvt 1 0\nvt 2 0\nvt 0 1\nvt 1 1\nvt 2 1\n"
          "f 1/1 2/2 5/5\nf 1/1 5/5 4/4\nf 2/2 3/3 6/6\nf 2/2 6/6 5/5\nstitch 1 0 2 0.5\n");
    write(d / "frame0.obj", "v 0 -1 0\nv 1 -1 0\nv 0 -1 1\nf 1 2 3\n");
    write(d / "frame1.obj", "v 0 -2 0\nv 1 -2 0\nv 0 -2 1\nf 1 2 3\n");
    ::setenv("CLOTHCD_DATA", d.c_str(), 1);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fs::path file = scratch() / "scene.json";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const clothcd::sim::Scene s = clothcd::sim::load_scene(file);
    const int n = static_cast<int>(s.cloth.positions.size());
    if (n < 3 || s.cloth.faces.empty()) std::abort();
    for (const auto& f : s.cloth.faces) {
      for (int i : f) {
        if (i < 0 || i >= n) std::abort();
      }
    }
    for (const auto& p : s.pins) {
      for (int v : p.vertices) {
        if (v < 0 || v >= n) std::abort();
      }
    }
    if (s.frames < 1 || !(s.frame_dt > 0)) std::abort();
  } catch (const clothcd::InputError&) {
  }
  return 0;
}
