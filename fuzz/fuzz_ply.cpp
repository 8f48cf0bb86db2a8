// Fuzzes the PLY reader (ASCII and binary, both endians): InputError or a valid mesh.
#include "fuzz_mesh_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return clothcd::fuzz::read_mesh_bytes(data, size, ".ply",
                                        [](const auto& path) { return clothcd::read_ply(path); });
}
