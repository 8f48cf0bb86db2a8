#pragma once
// The mesh readers take paths, so each input is written to a per-process scratch file first.

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"

namespace clothcd::fuzz {

/// Writes the fuzzer's bytes to this process's scratch file for `extension` and returns its path.
inline std::filesystem::path scratch_file(const std::uint8_t* data, std::size_t size,
                                          const char* extension) {
  std::filesystem::path path = std::filesystem::temp_directory_path() /
                               ("clothcd-fuzz-" + std::to_string(::getpid()) + extension);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

template <class Reader>
int read_mesh_bytes(const std::uint8_t* data, std::size_t size, const char* extension,
                    Reader&& read) {
  const std::filesystem::path path = scratch_file(data, size, extension);
  try {
    const TriangleMesh mesh = read(path);
    const int n = static_cast<int>(mesh.vertices.size());
    for (const auto& v : mesh.vertices) {
      if (!v.allFinite()) std::abort();
    }
    for (const auto& f : mesh.faces) {
      for (int i : f) {
        if (i < 0 || i >= n) std::abort();
      }
    }
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace clothcd::fuzz
