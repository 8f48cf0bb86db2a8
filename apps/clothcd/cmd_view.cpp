// `clothcd view DIR --out page.html` and `clothcd view --t0 A --t1 B --json RESULT.json --out
// page.html`: one self-contained HTML page to look at a simulation or a detection step in a
// browser (clothcd/view/page.hpp).
#include <fmt/format.h>

#include <memory>
#include <string>

#include "clothcd/core/error.hpp"
#include "clothcd/view/page.hpp"
#include "command.hpp"

// A namespace of its own: the commands are compiled together (unity build).
namespace {
namespace view_command {

struct ViewArgs {
  std::string dir, t0, t1, json, out;
  int first = 0, last = -1, step = 1;
  double contact_distance = 0.0;
  bool no_body = false, no_contact = false;
};

std::string megabytes(std::size_t bytes) {
  return fmt::format("{:.1f} MB", static_cast<double>(bytes) / 1e6);
}

int run(const ViewArgs& a) {
  const bool step_mode = !a.t0.empty() || !a.t1.empty() || !a.json.empty();
  if (step_mode == !a.dir.empty()) {
    throw clothcd::InputError(
        "clothcd view: give either a simulation folder (clothcd view DIR --out page.html) or a "
        "detection step (clothcd view --t0 A --t1 B --json RESULT.json --out page.html)");
  }
  clothcd::view::PageSummary s;
  if (step_mode) {
    if (a.t0.empty() || a.t1.empty() || a.json.empty()) {
      throw clothcd::InputError("clothcd view: a detection step needs --t0, --t1 and --json");
    }
    s = clothcd::view::write_detection_page(a.t0, a.t1, a.json, a.out);
    fmt::print("{}: {} hits, {} (geometry {} packed to {})\n", a.out, s.hits, megabytes(s.bytes),
               megabytes(s.data_bytes), megabytes(s.packed_bytes));
  } else {
    clothcd::view::SequenceOptions opt;
    opt.first = a.first;
    opt.last = a.last;
    opt.step = a.step;
    opt.body = !a.no_body;
    opt.contact = !a.no_contact;
    opt.contact_distance = a.contact_distance;
    s = clothcd::view::write_sequence_page(a.dir, a.out, opt);
    for (const std::string& n : s.notes)
      fmt::print(stderr, "clothcd view: {}\n", n);
    fmt::print("{}: {} frames{}{}{}, {} (geometry {} packed to {})\n", a.out, s.frames,
               s.body ? ", body" : "", s.strain ? ", strain" : "", s.contact ? ", contact" : "",
               megabytes(s.bytes), megabytes(s.data_bytes), megabytes(s.packed_bytes));
  }
  return 0;
}

const bool registered = clothcd::app::register_command(
    "view", "Write an HTML page to look at a simulation or a detection step in a browser",
    [](CLI::App& sub) -> std::function<int()> {
      auto a = std::make_shared<ViewArgs>();
      sub.add_option("dir", a->dir, "Output folder of `clothcd simulate`");
      sub.add_option("--t0", a->t0, "Detection step: the frame at its start");
      sub.add_option("--t1", a->t1, "Detection step: the frame at its end");
      sub.add_option("--json", a->json, "Detection step: the result of `clothcd detect --json`");
      sub.add_option("--out", a->out, "The HTML file to write")->required();
      sub.add_option("--first", a->first, "Simulation: first frame (default 0)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--last", a->last, "Simulation: last frame (default: the last complete)");
      sub.add_option("--step", a->step, "Simulation: every N-th frame (default 1)")
          ->check(CLI::PositiveNumber);
      sub.add_option("--contact-distance", a->contact_distance,
                     "Simulation: distance that counts as contact, m (default: the run's "
                     "thickness, or 0.002)")
          ->check(CLI::NonNegativeNumber);
      sub.add_flag("--no-body", a->no_body, "Simulation: leave the body out");
      sub.add_flag("--no-contact", a->no_contact,
                   "Simulation: no contact colouring (skips a proximity query per frame)");
      return [a]() { return run(*a); };
    });

}  // namespace view_command
}  // namespace
