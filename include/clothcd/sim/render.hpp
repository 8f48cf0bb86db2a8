#pragma once
/// @file
/// A small software renderer for looking at simulated frames: orthographic view, z-buffer,
/// two-sided Lambert shading, written as an RGB PNG (libpng).

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "clothcd/mesh/topology.hpp"
#include "clothcd/sim/elements.hpp"

namespace clothcd::sim {

struct RenderMesh {
  const std::vector<Vec3>* positions = nullptr;
  const std::vector<Face>* faces = nullptr;
  std::array<double, 3> color{0.8, 0.8, 0.8};  ///< RGB in [0, 1]
};

struct RenderOptions {
  int width = 800;
  int height = 800;
  /// "front" (camera on +z looking at -z, y up), "back", "side" (+x), "top" (+y), "iso".
  std::string view = "front";
};

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;  ///< row-major, top row first
};

/// Renders the meshes, fitted to the image with a small margin. Throws InputError on an unknown
/// view or a non-positive size.
[[nodiscard]] Image render(const std::vector<RenderMesh>& meshes, const RenderOptions& options);

/// Writes `image` as a PNG through write_file_atomic (clothcd/core/atomic_file.hpp). Throws
/// OutputError (a std::runtime_error) naming the file and the reason when it cannot be written.
void write_png(const std::filesystem::path& path, const Image& image);

}  // namespace clothcd::sim
