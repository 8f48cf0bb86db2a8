// One CCD step and one proximity query of the self detector on a folding sheet of a given number
// of triangles (crumpled_sheet, an n x n grid of 2 n^2 triangles), in a process of its own so
// that the peak memory is this size's: scripts/detect_scale_bench.sh runs it for each size and
// writes the table of docs/results/scale.md.
//
// The step is a simulator-sized part of the sheet's folding motion: from 80% of the way to 80%
// plus 1/n, so a vertex moves about a third of a cell (the geometry is the same surface at every
// size, resolved finer). The proximity query is at the step's end, within half a cell.
//
// Usage: scale_bench TRIANGLES [THREADS] [CULLING none|sound]. Prints one tab-separated line:
// triangles, threads, build s, refit s, traverse s, narrow s, detect s (wall), proximity s,
// candidate triangle pairs, VF+EE feature tests, VF+EE collisions, proximity pairs, peak MiB.
// The peak is the process's resident set at its highest: the detector, the step's two position
// matrices and the results (the generator's own positions are freed before the detector is
// built).

#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "clothcd/detect/detector.hpp"
#include "clothcd/research/procedural.hpp"

namespace {

using namespace clothcd;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Peak resident set of this process (VmHWM), MiB; -1 where /proc is unavailable.
double peak_mib() {
  std::ifstream in("/proc/self/status");
  std::string key;
  while (in >> key) {
    if (key == "VmHWM:") {
      double kib = 0;
      in >> kib;
      return kib / 1024.0;
    }
    std::getline(in, key);
  }
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s TRIANGLES [THREADS] [CULLING none|sound]\n", argv[0]);
    return 2;
  }
  const long triangles = std::atol(argv[1]);
  const int threads = argc > 2 ? std::atoi(argv[2]) : 2;
  const std::string culling = argc > 3 ? argv[3] : "none";
  if (triangles < 2 || threads < 1 || (culling != "none" && culling != "sound")) {
    std::fprintf(stderr, "bad arguments (TRIANGLES >= 2, THREADS >= 1, CULLING none|sound)\n");
    return 2;
  }
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  const int n = static_cast<int>(std::lround(std::sqrt(triangles / 2.0)));

  research::ProceduralScene s = research::crumpled_sheet(n, 7);
  const double a = 0.8, b = 0.8 + 1.0 / n;
  const Positions x0 = s.v_t0 + a * (s.v_t1 - s.v_t0);
  const Positions x1 = s.v_t0 + b * (s.v_t1 - s.v_t0);
  // What stays alive is what a caller holds: the step's positions and the faces, which the
  // detector takes over. The generator's own positions would add to the peak.
  s.v_t0 = Positions();
  s.v_t1 = Positions();
  const std::size_t faces = s.faces.size();

  DetectOptions o;
  o.culling = culling == "sound" ? Culling::Sound : Culling::None;
  auto t = Clock::now();
  SelfDetector det(std::move(s.faces), s.num_vertices, x0, o);
  const double build = since(t);

  t = Clock::now();
  const DetectResult r = det.detect(x0, x1);
  const double detect = since(t);

  t = Clock::now();
  const ProximityResult p = det.proximity(x1, 0.5 / n);
  const double proximity = since(t);

  const DetectStats& st = r.stats;
  std::printf("%zu\t%d\t%.3f\t%.3f\t%.3f\t%.3f\t%.3f\t%.3f\t%llu\t%llu\t%zu\t%zu\t%.0f\n", faces,
              threads, build, st.time_refit, st.time_traverse, st.time_narrow, detect, proximity,
              static_cast<unsigned long long>(st.triangle_pairs),
              static_cast<unsigned long long>(st.vf_tests + st.ee_tests), r.vf.size() + r.ee.size(),
              p.vf.size() + p.ee.size(), peak_mib());
  return 0;
}
