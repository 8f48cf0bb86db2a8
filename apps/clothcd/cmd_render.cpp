// `clothcd render DIR --frames 0,10,20 --out DIR/png`: PNG pictures of simulated frames (garment,
// plus the body at the frame's time when the scene has one).
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/sim/render.hpp"
#include "clothcd/sim/scene.hpp"
#include "command.hpp"

// A namespace of its own: the commands are compiled together (unity build).
namespace {
namespace render_command {

namespace fs = std::filesystem;

struct RenderArgs {
  std::string dir;
  std::string out;
  std::vector<int> frames;
  std::vector<std::string> views{"front"};
  int size = 800;
  bool no_body = false;
};

int run(const RenderArgs& a) {
  const fs::path dir = a.dir;
  const fs::path manifest_path = dir / "manifest.json";
  std::ifstream in(manifest_path);
  if (!in)
    throw clothcd::InputError(
        fmt::format("{}: cannot open (not a simulate output folder?)", manifest_path.string()));
  nlohmann::json manifest;
  try {
    manifest = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw clothcd::InputError(
        fmt::format("{}: invalid JSON: {}", manifest_path.string(), e.what()));
  }
  const std::string ext = manifest.value("mesh_format", "obj");
  const int complete = manifest.value("complete_frames", 0);
  const double dt = manifest.value("frame_dt", 0.04);
  std::vector<int> frames = a.frames;
  if (frames.empty()) frames = {0, complete / 2, complete};
  // Check every input before writing anything.
  std::vector<fs::path> files;
  for (int f : frames) {
    if (f < 0 || f > complete) {
      throw clothcd::InputError(fmt::format("{}: frame {} is not complete (complete frames: 0..{})",
                                            manifest_path.string(), f, complete));
    }
    files.push_back(dir / fmt::format("frame_{:04d}.{}", f, ext));
    if (!fs::exists(files.back())) {
      throw clothcd::InputError(fmt::format("{}: missing", files.back().string()));
    }
  }
  for (const std::string& v : a.views)
    (void)clothcd::sim::render({}, {8, 8, v});  // rejects unknown views up front
  std::unique_ptr<clothcd::sim::Scene> scene;
  if (!a.no_body && manifest.contains("scene_file")) {
    const fs::path sf = manifest.at("scene_file").get<std::string>();
    if (fs::exists(sf)) {
      scene = std::make_unique<clothcd::sim::Scene>(clothcd::sim::load_scene(sf));
    } else {
      fmt::print(stderr, "scene file {} not found: rendering the garment only\n", sf.string());
    }
  }
  const fs::path out = a.out.empty() ? dir / "png" : fs::path(a.out);
  fs::create_directories(out);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const clothcd::TriangleMesh cloth = clothcd::read_mesh(files[i]);
    std::vector<clothcd::sim::RenderMesh> meshes;
    meshes.push_back({&cloth.vertices, &cloth.faces, {0.35, 0.55, 0.9}});
    std::vector<clothcd::sim::Vec3> body;
    if (scene && scene->body) {
      scene->body->positions_at(frames[i] * dt, body);
      meshes.push_back({&body, &scene->body->faces(), {0.85, 0.8, 0.75}});
    }
    for (const std::string& v : a.views) {
      const auto img = clothcd::sim::render(meshes, {a.size, a.size, v});
      const fs::path png = out / fmt::format("frame_{:04d}_{}.png", frames[i], v);
      clothcd::sim::write_png(png, img);
      fmt::print("{}\n", png.string());
    }
  }
  return 0;
}

const bool registered = clothcd::app::register_command(
    "render", "Render simulated frames (garment and body) to PNG",
    [](CLI::App& sub) -> std::function<int()> {
      auto args = std::make_shared<RenderArgs>();
      sub.add_option("dir", args->dir, "Output folder of `clothcd simulate`")->required();
      sub.add_option("--frames", args->frames,
                     "Frames to render, e.g. 0,10,20 (default: first, middle, last)")
          ->delimiter(',');
      sub.add_option("--out", args->out, "Folder for the PNG files (default: DIR/png)");
      sub.add_option("--view", args->views, "front, back, side, top, iso (comma-separated)")
          ->delimiter(',');
      sub.add_option("--size", args->size, "Image width and height in pixels (default 800)")
          ->check(CLI::Range(16, 8192));
      sub.add_flag("--no-body", args->no_body, "Draw the garment only");
      return [args]() { return run(*args); };
    });

}  // namespace render_command
}  // namespace
