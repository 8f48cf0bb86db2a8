// `clothcd simulate SCENE.json --out DIR`: runs the cloth simulator, one mesh per frame.
#include <fmt/format.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

#include "clothcd/sim/frame_io.hpp"
#include "clothcd/sim/scene.hpp"
#include "clothcd/sim/simulation.hpp"
#include "command.hpp"

// A namespace of its own: the commands are compiled together (unity build).
namespace {
namespace simulate_command {

struct SimulateArgs {
  std::string scene;
  std::string out;
  int frames = -1;
  bool resume = false;
  int resume_at = -1;
  int keep_states = 0;
  int threads = 0;
};

std::string clock_text(double seconds) {
  if (!(seconds >= 0.0) || seconds > 1e7) return "--:--";
  const long s = static_cast<long>(seconds + 0.5);
  return s >= 3600 ? fmt::format("{}h{:02d}m", s / 3600, (s / 60) % 60)
                   : fmt::format("{}m{:02d}s", s / 60, s % 60);
}

/// A bar on a terminal, one plain line per frame otherwise (logs, CI).
class Progress {
 public:
  explicit Progress(int first_frame) : first_(first_frame), tty_(isatty(fileno(stderr)) != 0) {}

  void frame(const clothcd::sim::FrameStats& s, int total) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const int done_here = s.frame - first_;
    const double fps = elapsed > 0.0 ? done_here / elapsed : 0.0;
    const double eta = fps > 0.0 ? (total - s.frame) / fps : -1.0;
    if (tty_) {
      const int width = 30;
      const int filled = total > 0 ? width * s.frame / total : width;
      fmt::print(stderr, "\r[{}{}] {}/{} frames  {:.2f} fps  ETA {}  ", std::string(filled, '#'),
                 std::string(width - filled, ' '), s.frame, total, fps, clock_text(eta));
      if (s.frame == total) fmt::print(stderr, "\n");
    } else {
      fmt::print(
          stderr,
          "frame {}/{}: {} substeps, {} PCG iterations (max {}), {:.2f} s ({:.2f} s "
          "collisions), stretch {:.3f}, {} CCD hits, {} zones, intersections {}/{}, ETA {}\n",
          s.frame, total, s.substeps, s.pcg_iterations, s.max_pcg_iterations, s.seconds,
          s.collision.seconds, s.max_stretch, s.collision.ccd_hits, s.collision.zones,
          s.self_intersections, s.body_intersections, clock_text(eta));
    }
    std::fflush(stderr);
  }

 private:
  int first_;
  bool tty_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

const bool registered = clothcd::app::register_command(
    "simulate", "Simulate a cloth scene (JSON) and write one mesh per frame plus a manifest",
    [](CLI::App& sub) -> std::function<int()> {
      auto args = std::make_shared<SimulateArgs>();
      sub.add_option("scene", args->scene, "Scene file (JSON), e.g. scenes/sphere-drop.json")
          ->required();
      sub.add_option("--out", args->out, "Output folder (created if missing)")->required();
      sub.add_option("--frames", args->frames, "Frames to reach (default: the scene's)")
          ->check(CLI::NonNegativeNumber);
      sub.add_flag("--resume", args->resume, "Continue from the last complete frame in --out");
      sub.add_option("--resume-at", args->resume_at,
                     "Continue from this frame's kept state in --out (see --keep-states); the "
                     "later frames are dropped and simulated again")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--keep-states", args->keep_states,
                     "Also keep the state of every N-th frame, for --resume-at (default 0: the "
                     "last frame's only)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--threads", args->threads, "Worker threads (default: all cores)")
          ->check(CLI::PositiveNumber);
      return [args]() {
        std::optional<tbb::global_control> limit;
        if (args->threads > 0) {
          limit.emplace(tbb::global_control::max_allowed_parallelism,
                        static_cast<std::size_t>(args->threads));
        }
        clothcd::sim::Scene scene = clothcd::sim::load_scene(args->scene);
        // Locked before the (possibly slow) setup, so that a second run on the folder refuses
        // at once; after the scene is read, so that a bad scene leaves no folder behind.
        const clothcd::sim::OutputLock lock(args->out);
        clothcd::sim::Simulation sim(std::move(scene));
        const auto& m = sim.model();
        fmt::print(
            stderr,
            "{}: {} vertices, {} triangles ({} slivers), {} hinges, {} stitches, {} pins{}; "
            "collision handling: {}\n",
            sim.scene().name, m.num_vertices(), m.topology().num_faces(), m.num_slivers(),
            m.hinges().size(), m.stitches().size(), sim.scene().pins.size(),
            sim.scene().body
                ? fmt::format(", body with {} vertices", sim.scene().body->num_vertices())
                : std::string(),
            sim.scene().collisions
                ? fmt::format("self {}, body {}, thickness {} m, {} CCD passes",
                              sim.scene().contact.self, sim.scene().contact.body,
                              sim.scene().contact.thickness, sim.scene().contact.ccd_iterations)
                : std::string("none"));
        if (const auto& r = sim.initial_repair(); r.pairs_before > 0) {
          fmt::print(stderr,
                     "starting shape: {} self-crossing pairs, {} after moving {} vertices (at most "
                     "{:.3f} mm)\n",
                     r.pairs_before, r.pairs_after, r.moves, 1e3 * r.largest_move);
        }
        clothcd::sim::RunOptions opt;
        opt.out = args->out;
        opt.frames = args->frames;
        opt.resume = args->resume || args->resume_at >= 0;
        opt.resume_at = args->resume_at;
        opt.keep_states = args->keep_states;
        opt.lock = &lock;
        if (args->resume && args->resume_at < 0 &&
            !std::filesystem::exists(opt.out / "manifest.json")) {
          fmt::print(stderr, "no manifest in {}: starting from frame 0\n", args->out);
        }
        std::unique_ptr<Progress> progress;
        opt.on_frame = [&progress](const clothcd::sim::FrameStats& s, int total) {
          if (!progress) progress = std::make_unique<Progress>(s.frame - 1);
          progress->frame(s, total);
        };
        const auto frames = clothcd::sim::run_simulation(sim, opt);
        double seconds = 0.0, coll = 0.0;
        long long iters = 0, worst_self = 0, worst_body = 0;
        int substeps = 0;
        for (const auto& f : frames) {
          seconds += f.seconds;
          coll += f.collision.seconds;
          worst_self = std::max(worst_self, f.self_intersections);
          worst_body = std::max(worst_body, f.body_intersections);
          iters += f.pcg_iterations;
          substeps += f.substeps;
        }
        fmt::print(
            "{} frames simulated in {:.2f} s ({:.3f} s/frame, {:.1f} PCG iterations per "
            "substep); {:.0f}% in collision handling; most intersecting pairs in a frame: {} "
            "self, {} body; now at frame {}; output in {}\n",
            frames.size(), seconds, frames.empty() ? 0.0 : seconds / frames.size(),
            substeps > 0 ? double(iters) / substeps : 0.0,
            seconds > 0 ? 100.0 * coll / seconds : 0.0, worst_self, worst_body, sim.frame(),
            args->out);
        return 0;
      };
    });

}  // namespace simulate_command
}  // namespace
