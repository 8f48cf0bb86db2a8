// The simulator's per-frame intersection count on the 58,687-triangle multilayer garment on the
// kick body (scenes/multilayer-kick.json), 2 threads: cloth-cloth and cloth-body pairs, timed
// apart, with the counter's trees first built on the state itself or on the scene's starting
// shape (then refit, or rebuilt when they have loosened, as in a simulation); and a cloth tree's
// build, full or boxes only. The state is the scene's start, or the state file named by
// CLOTHCD_BENCH_STATE (a `state_NNNN.bin` that `clothcd simulate --keep-states` wrote for this
// scene), at its frame's time. Skips when the shared data is absent.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cstdlib>
#include <filesystem>
#include <memory>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/sim/frame_io.hpp"
#include "clothcd/sim/intersections.hpp"
#include "clothcd/sim/scene.hpp"
#include "clothcd/sim/simulation.hpp"

namespace {

using namespace clothcd;
using namespace clothcd::sim;

struct Setup {
  std::unique_ptr<Simulation> sim;
  std::vector<Vec3> x, body;
};

const Setup* setup() {
  static std::unique_ptr<Setup> s = []() -> std::unique_ptr<Setup> {
    const char* env = std::getenv("CLOTHCD_DATA");
    const std::filesystem::path data(env != nullptr && *env != 0 ? env : CLOTHCD_DATA_DEFAULT);
    if (!std::filesystem::exists(data / "garments/multilayer/drape.obj")) return nullptr;
    if (env == nullptr || *env == 0) setenv("CLOTHCD_DATA", data.c_str(), 1);  // for the scene
    auto r = std::make_unique<Setup>();
    r->sim = std::make_unique<Simulation>(
        load_scene(std::filesystem::path(CLOTHCD_SOURCE_DIR) / "scenes/multilayer-kick.json"));
    if (const char* st = std::getenv("CLOTHCD_BENCH_STATE"); st != nullptr && *st != 0) {
      int frame = 0;
      ClothState state = read_state(st, r->sim->model().num_vertices(), frame);
      r->sim->set_state(std::move(state), frame);
    }
    r->x = r->sim->state().x;
    r->body = r->sim->body_positions();
    return r;
  }();
  return s.get();
}

// range(0): 0 cloth-cloth, 1 cloth-body; range(1): trees first built on 0 the state, 1 the start.
void BM_IntersectionCount(benchmark::State& state) {
  const Setup* s = setup();
  if (s == nullptr) {
    state.SkipWithError("multilayer garment not found (set CLOTHCD_DATA)");
    return;
  }
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  const Simulation& sim = *s->sim;
  IntersectionCounter counter(sim.model().topology(), sim.model().seam_links(),
                              sim.scene().body->faces(), static_cast<int>(s->body.size()));
  const std::vector<Vec3>& x = s->x;
  std::size_t pairs = 0;
  // The trees are built at the first call.
  const std::vector<Vec3> build_at = state.range(1) == 1 ? sim.model().initial_positions() : x;
  (void)counter.self_pairs(build_at);
  (void)counter.body_pairs(build_at, s->body);
  for (auto _ : state) {
    pairs =
        state.range(0) == 0 ? counter.self_pairs(x).size() : counter.body_pairs(x, s->body).size();
    benchmark::DoNotOptimize(pairs);
  }
  state.counters["pairs"] = static_cast<double>(pairs);
}

// Building the cloth tree at the state (median splits, one thread); range(0): 0 with the
// topology flags and contours of sound culling, 1 boxes only.
void BM_ClothTreeBuild(benchmark::State& state) {
  const Setup* s = setup();
  if (s == nullptr) {
    state.SkipWithError("multilayer garment not found (set CLOTHCD_DATA)");
    return;
  }
  const Topology& topo = s->sim->model().topology();
  for (auto _ : state) {
    Bvh b = state.range(0) == 0 ? Bvh(topo, s->x, BvhBuild::Spatial)
                                : Bvh::boxes_only(topo, s->x, BvhBuild::Spatial);
    benchmark::DoNotOptimize(b);
  }
}

}  // namespace

BENCHMARK(BM_ClothTreeBuild)
    ->ArgName("boxes_only")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_IntersectionCount)
    ->ArgNames({"body", "built_at_start"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
