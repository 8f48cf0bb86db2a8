// `clothcd experiment --scene S ... --out DIR`: every cone policy x culling rule x BVH build over
// the same recorded frames; writes steps.csv, table1.md, table2.md, misses.md, spread.md,
// summary.md and the figures fig5.png / fig6.png (scripts/plot_experiment.py with Debian's
// python3-matplotlib). `clothcd experiment --in-situ SCENE.json... --frames N`: the self CCD's
// culling settings inside the simulator instead (in_situ.cpp).
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/experiment/experiment.hpp"
#include "command.hpp"
#include "in_situ.hpp"

// A namespace of its own: the commands are compiled together (unity build).
namespace {
namespace experiment_command {

namespace fs = std::filesystem;
using namespace clothcd;
using namespace clothcd::experiment;

struct Args {
  std::vector<std::string> scenes;
  std::string out;
  int steps = -1;
  std::vector<std::string> policies{"provot", "proposed", "exact"};
  std::vector<std::string> cullings{"cone", "gated", "sound"};
  std::vector<std::string> builds{"spatial", "patch"};
  int threads = 0;
  int optimal_every = 10;
  int optimal_max_faces = 0;
  bool no_plots = false;
  std::string python = "/usr/bin/python3";
  std::string plot_script;
  std::string scenes_dir;
  std::vector<std::string> in_situ;
  bool in_situ_tables = false;
  int frames = 6;
  int every = 1;
  int timing_every = 0;
  int timing_repeats = 3;
  std::vector<int> timing_threads{1, 2};
  std::vector<std::string> timing_cullings{"cone", "gated", "sound"};
  std::string command;
};

// The source tree (scenes/, scripts/): where the tool was built from, else the working folder.
fs::path source_dir() {
#ifdef CLOTHCD_SOURCE_DIR
  if (fs::exists(fs::path(CLOTHCD_SOURCE_DIR) / "scripts")) return CLOTHCD_SOURCE_DIR;
#endif
  return fs::current_path();
}

fs::path data_root() {
  if (const char* env = std::getenv("CLOTHCD_DATA"); env != nullptr && *env != '\0') return env;
  return source_dir() / ".." / "shared" / "data";
}

std::string clock_text(double seconds) {
  if (!(seconds >= 0.0) || seconds > 1e7) return "--:--";
  const long s = static_cast<long>(seconds + 0.5);
  return s >= 3600 ? fmt::format("{}h{:02d}m", s / 3600, (s / 60) % 60)
                   : fmt::format("{}m{:02d}s", s / 60, s % 60);
}

// A bar with the time left on a terminal, one line per unit otherwise (logs, CI). The rate counts
// only the units run now, not those found complete in --out.
class Bar {
 public:
  void update(const Progress& p) {
    if (p.ran) ++ran_;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = ran_ > 0 ? elapsed / ran_ * (p.total - p.done) : -1.0;
    if (tty_) {
      const int width = 30;
      const int filled = p.total > 0 ? width * p.done / p.total : width;
      fmt::print(stderr, "\r[{}{}] {}/{} steps  ETA {}  {}        ", std::string(filled, '#'),
                 std::string(width - filled, ' '), p.done, p.total, clock_text(eta), p.what);
      if (p.done == p.total) fmt::print(stderr, "\n");
    } else {
      fmt::print(stderr, "[{}/{}] {}{}, ETA {}\n", p.done, p.total, p.what,
                 p.ran ? "" : " (already in --out)", clock_text(eta));
    }
    std::fflush(stderr);
  }

 private:
  bool tty_ = isatty(fileno(stderr)) != 0;
  int ran_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

int parse_count(const std::string& text, const std::string& spec, int min) {
  if (text.empty() || text.size() > 6 ||
      text.find_first_not_of("0123456789") != std::string::npos || std::stoi(text) < min) {
    throw InputError(
        fmt::format("--scene '{}': expected NAME@STEPS, NAME@FIRST:STEPS or a trailing %EVERY "
                    "(STEPS, EVERY >= 1, FIRST >= 0)",
                    spec));
  }
  return std::stoi(text);
}

Sequence resolve_scene_range(const std::string& s, const Args& a);
Sequence resolve_scene_window(const std::string& spec, const Args& args);

// `NAME@N`: at most N CD calls for that scene (overrides --steps); `NAME@F:N`: the N calls from
// frame F on (the frames before F are simulated or read, then dropped). A trailing `%E` runs
// every E-th of those calls only (overrides --every).
Sequence resolve_scene(const std::string& full, const Args& args) {
  std::string spec = full;
  int every = args.every;
  if (const auto pc = spec.rfind('%'); pc != std::string::npos) {
    every = parse_count(spec.substr(pc + 1), full, 1);
    spec = spec.substr(0, pc);
  }
  Sequence q = resolve_scene_window(spec, args);
  q.every = every;
  return q;
}

Sequence resolve_scene_window(const std::string& spec, const Args& args) {
  const auto at = spec.rfind('@');
  if (at == std::string::npos) return resolve_scene_range(spec, args);
  Args a = args;
  const std::string range = spec.substr(at + 1);
  int first = 0;
  if (const auto colon = range.find(':'); colon != std::string::npos) {
    first = parse_count(range.substr(0, colon), spec, 0);
    a.steps = first + parse_count(range.substr(colon + 1), spec, 1);
  } else {
    a.steps = parse_count(range, spec, 1);
  }
  Sequence q = resolve_scene_range(spec.substr(0, at), a);
  if (first > 0) {
    if (first + 1 >= static_cast<int>(q.frames.size())) {
      throw InputError(fmt::format("--scene '{}': only {} frames", spec, q.frames.size()));
    }
    drop_frames_before(q, first);
    // Another window is another scene: its results must not be reused for this one.
    q.name += fmt::format("-from{}", first);
    q.source += fmt::format(", from frame {}: step k = frames {}+k -> {}+k+1", first, first, first);
  }
  return q;
}

Sequence resolve_scene_range(const std::string& s, const Args& a) {
  const int max_frames = a.steps >= 0 ? a.steps + 1 : -1;
  std::string proc = s.starts_with("proc:") ? s.substr(5) : s;
  for (const auto& n : procedural_names()) {
    if (proc == n) {
      Sequence q = procedural_sequence(n);
      if (max_frames >= 0 && static_cast<int>(q.frames.size()) > max_frames)
        q.frames.resize(static_cast<std::size_t>(std::max(2, max_frames)));
      return q;
    }
  }
  if (s == "cloth_ball") {
    const fs::path dir = data_root() / "cloth-ball" / "frames";
    if (!fs::is_directory(dir)) {
      throw InputError(
          fmt::format("cloth_ball: {} not found; set CLOTHCD_DATA to the shared data "
                      "folder",
                      dir.string()));
    }
    Sequence q = load_frame_folder(dir, max_frames, "cloth_ball");
    return q;
  }
  if (fs::is_directory(s)) return load_frame_folder(s, max_frames);
  fs::path scene_file;
  if (fs::is_regular_file(s) && fs::path(s).extension() == ".json") {
    scene_file = s;
  } else {
    const fs::path dir = a.scenes_dir.empty() ? source_dir() / "scenes" : fs::path(a.scenes_dir);
    scene_file = dir / (s + ".json");
    if (!fs::is_regular_file(scene_file)) {
      throw InputError(fmt::format(
          "--scene '{}': not a folder of frames, a scene file, cloth_ball, a procedural sequence "
          "or a scene in {}",
          s, dir.string()));
    }
  }
  const fs::path frames = fs::path(a.out) / "frames" / scene_file.stem();
  fmt::print(stderr, "{}: frames in {} (simulated if absent)\n", scene_file.string(),
             frames.string());
  return simulate_scene(scene_file, frames, a.steps >= 0 ? a.steps : -1, [](int k, int total) {
    fmt::print(stderr, "  simulated frame {}/{}\n", k, total);
  });
}

fs::path plot_script(const Args& a) {
  if (!a.plot_script.empty()) return a.plot_script;
  return source_dir() / "scripts" / "plot_experiment.py";
}

int run(const Args& a) {
  ExperimentOptions opt;
  opt.out = a.out;
  opt.policies.clear();
  for (const auto& p : a.policies)
    opt.policies.push_back(parse_policy(p, "--policies"));
  opt.cullings.clear();
  for (const auto& c : a.cullings)
    opt.cullings.push_back(parse_culling(c, "--cullings"));
  opt.builds.clear();
  for (const auto& b : a.builds)
    opt.builds.push_back(parse_build(b, "--builds"));
  if (opt.policies.empty() || opt.builds.empty()) {
    throw InputError("--policies and --builds need at least one value");
  }
  opt.optimal_every = a.optimal_every;
  opt.optimal_max_faces = a.optimal_max_faces;
  opt.timing_every = a.timing_every;
  opt.timing_repeats = a.timing_repeats;
  opt.timing_threads = a.timing_threads;
  opt.timing_cullings.clear();
  for (const auto& c : a.timing_cullings)
    opt.timing_cullings.push_back(parse_culling(c, "--timing-cullings"));
  opt.stamp = stamp(a.command, source_dir(),
                    a.threads > 0 ? fmt::format("{} (counting pass)", a.threads)
                                  : std::string("all cores (counting pass)"));
  if (a.timing_every > 0) {
    opt.stamp +=
        fmt::format("- timing pass: every {}-th CD call run, {} repeats, threads {}\n",
                    a.timing_every, a.timing_repeats, fmt::join(a.timing_threads, " and "));
  }
  std::optional<tbb::global_control> limit;
  if (a.threads > 0) {
    limit.emplace(tbb::global_control::max_allowed_parallelism,
                  static_cast<std::size_t>(a.threads));
  }
  fs::create_directories(opt.out);

  std::vector<Sequence> seqs;
  for (const auto& s : a.scenes) {
    seqs.push_back(resolve_scene(s, a));
    count_crossings(seqs.back());
    for (std::size_t i = 0; i + 1 < seqs.size(); ++i) {
      if (seqs[i].name == seqs.back().name) {
        throw InputError(fmt::format("--scene: two scenes named '{}'", seqs.back().name));
      }
    }
    fmt::print(stderr, "scene {}: {} triangles, {} vertices, {} CD calls ({})\n", seqs.back().name,
               seqs.back().faces.size(), seqs.back().num_vertices, seqs.back().steps(),
               seqs.back().source);
  }
  int total = 0;
  for (const auto& q : seqs)
    total += (q.steps() + q.every - 1) / q.every * static_cast<int>(opt.builds.size());
  fmt::print(stderr,
             "{} configurations + the unculled reference per build, {} CD steps; OPTIMAL spread "
             "angles on every {}-th step\n",
             opt.policies.size() * opt.cullings.size() * opt.builds.size(), total,
             opt.optimal_every);
  Bar bar;
  int done = 0;
  for (const auto& q : seqs) {
    run_sequence(
        q, opt, [&bar](const Progress& p) { bar.update(p); }, done, total);
    done += (q.steps() + q.every - 1) / q.every * static_cast<int>(opt.builds.size());
    write_reports(seqs, opt);  // after each scene, so the tables cover what is finished
  }
  write_reports(seqs, opt);
  int rc = 0;
  if (!a.no_plots) {
    const std::string err = run_plots(opt.out, plot_script(a), a.python);
    if (!err.empty()) {
      fmt::print(stderr, "clothcd: plots not made: {} (the CSV and markdown tables are written)\n",
                 err);
      rc = 1;
    }
  }
  fmt::print(
      "results in {}: steps.csv, spread.csv, table1.md, table2.md, misses.md, spread.md, "
      "summary.md{}\n",
      a.out, a.no_plots || rc != 0 ? "" : ", fig5.png, fig6.png");
  return rc;
}

const bool registered = clothcd::app::register_command(
    "experiment",
    "Run every cone policy x culling rule x BVH build over recorded frames; write the paper's "
    "tables and figures",
    [](CLI::App& sub) {
      auto a = std::make_shared<Args>();
      auto* scene =
          sub.add_option("--scene", a->scenes,
                         "folder of frames, scene name (scenes/NAME.json, simulated into "
                         "OUT/frames/NAME), scene .json file, cloth_ball, or a procedural sequence "
                         "(fold, stacked_sheets, winding_strip, crumpled_sheet, twisted_strip); "
                         "NAME@N: at most N "
                         "CD calls for that scene, NAME@F:N the N calls from frame F on; a "
                         "trailing %E runs every E-th of them only (e.g. dress-rumba%2)");
      sub.add_option("--out", a->out,
                     "output folder (results found there are reused); with --in-situ the "
                     "Markdown file or its folder (default docs/results/in_situ.md)");
      sub.add_option("--in-situ", a->in_situ,
                     "instead: simulate these scene files under no culling and the sound culling "
                     "with PROVOT, PROPOSED and EXACT cones, frame by frame in turn, check the "
                     "frames are identical and compare the self CCD's figures")
          ->excludes(scene);
      sub.add_flag("--in-situ-tables", a->in_situ_tables,
                   "rewrite the in-situ sections of table1.md and table2.md in the --out folder "
                   "from the in_situ.csv there, simulating nothing");
      sub.add_option("--frames", a->frames, "frames per scene with --in-situ (default 6)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--steps", a->steps, "at most this many CD calls (frame pairs) per scene")
          ->check(CLI::PositiveNumber);
      sub.add_option("--policies", a->policies, "cone policies: provot proposed exact");
      sub.add_option("--cullings", a->cullings, "culling rules: cone gated sound");
      sub.add_option("--builds", a->builds, "BVH builds: spatial patch");
      sub.add_option("--threads", a->threads, "worker threads (default: all cores)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--optimal-every", a->optimal_every,
                     "OPTIMAL cones (spread angles only) on every K-th step, 0: never")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--optimal-max-faces", a->optimal_max_faces,
                     "no OPTIMAL cones for scenes with more triangles than this (0: no limit)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--every", a->every,
                     "run the CD calls 0, E, 2E, ... of each scene only (default 1: all; "
                     "NAME%E sets it per scene)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--timing-every", a->timing_every,
                     "timing pass on every T-th run call: each configuration repeated, thread "
                     "counts and configurations interleaved; medians in timing.md (0: none)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--timing-repeats", a->timing_repeats,
                     "calls per configuration and thread count in the timing pass (default 3)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--timing-threads", a->timing_threads,
                     "thread counts of the timing pass (default 1 2; capped by --threads)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--timing-cullings", a->timing_cullings,
                     "culling rules timed in the timing pass (default cone gated sound)");
      sub.add_flag("--no-plots", a->no_plots, "skip fig5.png / fig6.png");
      sub.add_option("--python", a->python,
                     "interpreter with matplotlib (default /usr/bin/python3)");
      sub.add_option("--plot-script", a->plot_script,
                     "plot script (default: scripts/plot_experiment.py of the source tree)");
      sub.add_option("--scenes-dir", a->scenes_dir, "folder of scene files (default: scenes/)");
      return [a, &sub] {
        if (a->in_situ_tables) {
          clothcd::app::InSituArgs in;
          in.out = a->out;
          in.tables_only = true;
          return clothcd::app::run_in_situ(in);
        }
        if (!a->in_situ.empty()) {
          clothcd::app::InSituArgs in;
          in.scenes = a->in_situ;
          in.frames = a->frames;
          in.out = a->out;
          in.threads = a->threads;
          in.command = "clothcd experiment --in-situ";
          for (const auto& s : a->in_situ)
            in.command += " " + s;
          in.command += fmt::format(" --frames {}", a->frames);
          if (a->threads > 0) in.command += fmt::format(" --threads {}", a->threads);
          if (!a->out.empty()) in.command += " --out " + a->out;
          return clothcd::app::run_in_situ(in);
        }
        if (a->scenes.empty()) throw InputError("experiment: --scene or --in-situ is required");
        if (a->out.empty()) throw InputError("experiment: --out is required with --scene");
        a->command = "clothcd experiment";
        for (const auto& o : sub.get_options()) {
          if (o->count() == 0 || o->get_name() == "--help") continue;
          a->command += " " + o->get_name();
          if (o->get_expected_min() == 0) continue;  // a flag: its name says it
          for (const auto& r : o->results())
            a->command += " " + r;
        }
        return run(*a);
      };
    });

}  // namespace experiment_command
}  // namespace
