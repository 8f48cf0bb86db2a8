// Fuzzes the OBJ reader (with stitch lines): InputError or a valid mesh, never a crash.
#include "fuzz_mesh_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return clothcd::fuzz::read_mesh_bytes(data, size, ".obj", [](const auto& path) {
    auto contents = clothcd::read_obj_with_stitches(path);
    const int n = static_cast<int>(contents.mesh.vertices.size());
    for (const auto& s : contents.stitches) {
      if (s.i < 0 || s.i >= n || s.j < 0 || s.j >= n || s.k < 0 || s.k >= n) std::abort();
    }
    return contents.mesh;
  });
}
