// The full cloth_ball 92 -> 93 CCD step on 2 threads for PROVOT, PROPOSED and EXACT (sound and
// the paper's cone-only culling). Each configuration is first checked against the unculled run
// (sound must find exactly the same collisions), then timed. Skips when the data is absent.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <memory>

#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"

namespace {

using namespace clothcd;

struct Frames {
  TriangleMesh m0;
  Positions p0, p1;
};

const Frames* frames() {
  static std::unique_ptr<Frames> f = [] {
    const char* env = std::getenv("CLOTHCD_DATA");
    const std::filesystem::path root =
        std::filesystem::path(env != nullptr && *env != 0 ? env : CLOTHCD_DATA_DEFAULT) /
        "cloth-ball/frames";
    if (!std::filesystem::exists(root / "cloth_ball92.ply")) return std::unique_ptr<Frames>();
    auto fr = std::make_unique<Frames>();
    fr->m0 = read_mesh(root / "cloth_ball92.ply");
    fr->p0 = vertices_matrix(fr->m0);
    fr->p1 = vertices_matrix(read_mesh(root / "cloth_ball93.ply"));
    return fr;
  }();
  return f.get();
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

void BM_ClothBallStep(benchmark::State& state) {
  const Frames* f = frames();
  if (f == nullptr) {
    state.SkipWithError("cloth-ball data not found (set CLOTHCD_DATA)");
    return;
  }
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  research::DetectOptions o;
  o.policy = static_cast<ConePolicy>(state.range(0));
  const auto culling = static_cast<research::CullingRule>(state.range(1));
  research::set_culling_rule(o, culling);
  o.build = static_cast<BvhBuild>(state.range(2));
  o.research.verify = true;
  research::SelfDetector det(f->m0.faces, f->m0.num_vertices(), f->p0, o);
  // Check first: the sound mode misses nothing against the unculled traversal.
  const research::DetectResult check = det.detect(f->p0, f->p1);
  const research::Verification& missed = check.verification;
  if (culling == research::CullingRule::Sound &&
      (!missed.missed_vf.empty() || !missed.missed_ee.empty())) {
    state.SkipWithError("sound culling missed collisions");
    return;
  }
  o.research.verify = false;
  det.set_options(o);
  DetectResult r;
  // Process CPU time (all threads): on a shared, loaded machine the wall time mostly measures
  // the other processes; CPU time is what the step itself costs.
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    r = det.detect(f->p0, f->p1);
    benchmark::DoNotOptimize(r.vf.data());
  }
  state.counters["cpu_s"] = (process_cpu_seconds() - cpu0) / double(state.iterations());
  const DetectStats& s = r.stats;
  state.counters["tri_pairs"] = double(s.triangle_pairs);
  state.counters["vf_tests"] = double(s.vf_tests);
  state.counters["ee_tests"] = double(s.ee_tests);
  state.counters["np_culled"] = double(s.vf_np_culled + s.ee_np_culled);
  state.counters["vf_hits"] = double(s.vf_collisions);
  state.counters["ee_hits"] = double(s.ee_collisions);
  state.counters["culled_nodes"] = double(s.nodes_culled);
  state.counters["missed"] = double(missed.missed_vf.size() + missed.missed_ee.size());
  state.counters["t_refit"] = s.time_refit;
  state.counters["t_trav"] = s.time_traverse;
  state.counters["t_narrow"] = s.time_narrow;
}

// Args: policy (0 Provot, 1 Proposed, 2 Exact), culling (research::CullingRule: 0 none, 1 cone,
// 3 sound), build.
BENCHMARK(BM_ClothBallStep)
    ->ArgNames({"policy", "culling", "bvh"})
    ->Args({1, 0, 0})
    ->Args({0, 1, 0})
    ->Args({1, 1, 0})
    ->Args({2, 1, 0})
    ->Args({0, 3, 0})
    ->Args({1, 3, 0})
    ->Args({2, 3, 0})
    ->Args({2, 3, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
