// The cloth simulator: a scene file run into an output folder, as `clothcd simulate` does.
#include <fmt/format.h>
#include <pybind11/functional.h>
#include <pybind11/stl/filesystem.h>

#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "clothcd/sim/frame_io.hpp"
#include "clothcd/sim/scene.hpp"
#include "clothcd/sim/simulation.hpp"

namespace clothcd::python {
namespace {

py::object to_python(const std::string& json_text) {
  return py::module_::import("json").attr("loads")(json_text);
}

}  // namespace

void bind_sim(py::module_& m) {
  m.def(
      "simulate",
      [](const std::filesystem::path& scene, const std::filesystem::path& out,
         std::optional<int> frames, const py::object& progress, int threads, bool resume,
         int keep_states) {
        if (frames && *frames < 0) fail(fmt::format("frames must be >= 0, got {}", *frames));
        if (keep_states < 0) fail(fmt::format("keep_states must be >= 0, got {}", keep_states));
        sim::RunOptions opt;
        opt.out = out;
        opt.frames = frames.value_or(-1);
        opt.resume = resume;
        opt.keep_states = keep_states;
        if (!progress.is_none()) {
          opt.on_frame = [&progress](const sim::FrameStats& s, int total) {
            py::gil_scoped_acquire gil;
            progress(to_python(sim::frame_stats_json(s)), total);
          };
        }
        Workers workers(threads);
        const std::vector<sim::FrameStats> done = workers.run([&] {
          sim::Simulation simulation(sim::load_scene(scene));
          return sim::run_simulation(simulation, opt);
        });
        py::list out_stats;
        for (const auto& s : done)
          out_stats.append(to_python(sim::frame_stats_json(s)));
        return out_stats;
      },
      py::arg("scene_path"), py::arg("out"), py::arg("frames") = py::none(),
      py::arg("progress") = py::none(), py::kw_only(), py::arg("threads") = 0,
      py::arg("resume") = false, py::arg("keep_states") = 0,
      R"(Simulates a scene file (JSON, docs/simulator.md) into the folder `out`, like
`clothcd simulate`: frame_NNNN.obj|ply per frame, the last state and manifest.json.

frames: the frame to reach (default: the scene's count). progress: called after every frame
as progress(stats: dict, total_frames: int) (with the GIL; an exception it raises stops the run,
the frames already written stay valid). resume: continue from the folder's last complete frame.
Returns the statistics dict of every frame simulated (as in the manifest). The GIL is released
while the simulator runs. Raises ValueError for a bad scene (naming the file and key).)");
}

}  // namespace clothcd::python
