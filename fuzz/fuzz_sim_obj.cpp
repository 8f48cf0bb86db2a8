// Fuzzes the simulator's OBJ reader (cloth, pattern and body frames): InputError or data whose
// indices are in range and whose coordinates are finite, never a crash.
#include <cmath>
#include <cstdlib>

#include "clothcd/sim/obj_reader.hpp"
#include "fuzz_mesh_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = clothcd::fuzz::scratch_file(data, size, ".obj");
  try {
    const clothcd::sim::ObjData d = clothcd::sim::read_obj(path);
    const int nv = static_cast<int>(d.positions.size());
    const int nt = static_cast<int>(d.texcoords.size());
    for (const auto& p : d.positions) {
      if (!p.allFinite()) std::abort();
    }
    for (const auto& t : d.texcoords) {
      if (!t.allFinite()) std::abort();
    }
    if (d.face_texcoords.size() != d.faces.size()) std::abort();
    for (std::size_t f = 0; f < d.faces.size(); ++f) {
      for (int k = 0; k < 3; ++k) {
        if (d.faces[f][k] < 0 || d.faces[f][k] >= nv) std::abort();
        if (d.face_texcoords[f][k] < -1 || d.face_texcoords[f][k] >= nt) std::abort();
      }
    }
    for (const auto& s : d.stitches) {
      for (int v : {s.a, s.b, s.c}) {
        if (v < 0 || v >= nv) std::abort();
      }
      if (!std::isfinite(s.r)) std::abort();
    }
  } catch (const clothcd::InputError&) {
  }
  try {
    for (const auto& p : clothcd::sim::read_obj_positions(path)) {
      if (!p.allFinite()) std::abort();
    }
  } catch (const clothcd::InputError&) {
  }
  return 0;
}
