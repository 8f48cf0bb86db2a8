// Fuzzes the OBJ reader (with stitch lines and texture coordinates, and the vertices-only read of
// animation frames): InputError or valid data, never a crash.
#include <cmath>

#include "fuzz_mesh_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return clothcd::fuzz::read_mesh_bytes(data, size, ".obj", [](const auto& path) {
    // Vertices only first: it may accept a file the full read rejects (no faces, say).
    try {
      for (const auto& v : clothcd::read_obj_vertices(path)) {
        if (!v.allFinite()) std::abort();
      }
    } catch (const clothcd::InputError&) {
    }
    auto contents = clothcd::read_obj_with_stitches(path);
    const int n = static_cast<int>(contents.mesh.vertices.size());
    const int nt = static_cast<int>(contents.texcoords.size());
    for (const auto& s : contents.stitches) {
      if (s.i < 0 || s.i >= n || s.j < 0 || s.j >= n || s.k < 0 || s.k >= n) std::abort();
      if (!std::isfinite(s.r)) std::abort();
    }
    for (const auto& t : contents.texcoords) {
      if (!t.allFinite()) std::abort();
    }
    if (contents.face_texcoords.size() != contents.mesh.faces.size()) std::abort();
    for (const auto& corners : contents.face_texcoords) {
      for (int t : corners) {
        if (t < -1 || t >= nt) std::abort();
      }
    }
    return contents.mesh;
  });
}
