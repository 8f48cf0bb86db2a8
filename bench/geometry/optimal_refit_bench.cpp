// A full OPTIMAL refit (the optimal cone of every internal node's control directions, the boxes
// and the leaf cones) of the draped garments: dress_knife (29,456 triangles) and multilayer
// (58,687 triangles), the garment prefix of their drape.obj, over one step to a smooth
// perturbation of the drape (amplitude 1 cm, wavelength 0.2 m, seed 1: `clothcd detect
// --perturb 0.01`). Arguments: garment (0 dress, 1 multilayer), build (0 spatial, 1 patch),
// threads. Also the PROPOSED refit of the same tree, for scale, and the refit a CCD pass runs
// (boxes only, or boxes and cones from the simulator's 16-triangle floor or on every node): what
// the cones add to a pass. Skips when the shared data is absent.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <utility>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/topology.hpp"
#include "clothcd/research/procedural.hpp"
#include "clothcd/research/refit.hpp"

namespace {

using namespace clothcd;

struct Garment {
  std::unique_ptr<Topology> topology;
  std::vector<Eigen::Vector3d> v0, v1;
};

// The garment prefix of a drape.obj and its perturbed copy; null when the data is absent.
const Garment* garment(int which) {
  static std::map<int, std::unique_ptr<Garment>> cache;
  if (auto it = cache.find(which); it != cache.end()) return it->second.get();
  const char* env = std::getenv("CLOTHCD_DATA");
  const std::filesystem::path data(env != nullptr && *env != 0 ? env : CLOTHCD_DATA_DEFAULT);
  const auto [name, garment_vertices] =
      which == 0 ? std::pair{"dress_knife", 15'656} : std::pair{"multilayer", 30'464};
  const std::filesystem::path file = data / "garments" / name / "drape.obj";
  std::unique_ptr<Garment>& g = cache[which];
  if (!std::filesystem::exists(file)) return nullptr;
  const TriangleMesh drape = read_mesh(file);
  int nf = 0;
  while (nf < drape.num_faces() && *std::ranges::max_element(drape.faces[nf]) < garment_vertices) {
    ++nf;
  }
  const TriangleMesh m = submesh_prefix(drape, garment_vertices, nf);
  g = std::make_unique<Garment>();
  g->topology = std::make_unique<Topology>(m.faces, m.num_vertices());
  g->v0 = m.vertices;
  const Positions p1 = research::smooth_perturbation(vertices_matrix(m), 0.01, 0.2, 1);
  for (int i = 0; i < m.num_vertices(); ++i)
    g->v1.push_back(p1.row(i).transpose());
  return g.get();
}

// Times `refit(bvh, garment)` on the tree of the benchmark's garment, build and thread count;
// with `cone_stats`, reports the internal cones' mean half-angle and saturated count.
template <class Refit>
void refit_bench(benchmark::State& state, Refit&& refit, bool cone_stats) {
  const Garment* g = garment(static_cast<int>(state.range(0)));
  if (g == nullptr) {
    state.SkipWithError("garments not found (set CLOTHCD_DATA)");
    return;
  }
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(state.range(2)));
  Bvh bvh(*g->topology, g->v0, state.range(1) == 0 ? BvhBuild::Spatial : BvhBuild::Patch);
  for (auto _ : state) {
    refit(bvh, *g);
    benchmark::DoNotOptimize(bvh.nodes().data());
  }
  state.counters["triangles"] = g->topology->num_faces();
  if (!cone_stats) return;
  double sum = 0;
  int internal = 0, saturated = 0;
  for (std::size_t i = 0; i < bvh.nodes().size(); ++i) {
    if (bvh.nodes()[i].is_leaf()) continue;
    ++internal;
    saturated += bvh.cones()[i].saturated() ? 1 : 0;
    sum += std::min(bvh.cones()[i].half_angle, kSaturatedHalfAngle);
  }
  state.counters["internal_mean_deg"] = sum / std::max(1, internal) * 180 / std::numbers::pi;
  state.counters["saturated"] = saturated;
}

// The research refit with every node's cone by `rule`.
void research_refit_bench(benchmark::State& state, research::ConeRule rule) {
  refit_bench(
      state,
      [rule](Bvh& bvh, const Garment& g) {
        research::refit(bvh, g.v0, g.v1, RefitOptions{}, rule);
      },
      true);
}
void BM_OptimalRefit(benchmark::State& state) {
  research_refit_bench(state, research::ConeRule::Optimal);
}
void BM_ProposedRefit(benchmark::State& state) {
  research_refit_bench(state, research::ConeRule::Proposed);
}

// The product refit a CCD pass runs: boxes only (culling none), or boxes and PROPOSED cones
// from `min_triangles` triangles up (16: the simulator's sound culling; 0: every node).
void product_refit_bench(benchmark::State& state, bool cones, int min_triangles) {
  RefitOptions o;
  o.cones = cones;
  o.cone_min_triangles = min_triangles;
  refit_bench(
      state, [o](Bvh& bvh, const Garment& g) { bvh.refit(g.v0, g.v1, o); }, false);
}

void BM_BoxRefit(benchmark::State& state) {
  product_refit_bench(state, false, 0);
}
void BM_ConeRefit16(benchmark::State& state) {
  product_refit_bench(state, true, 16);
}
void BM_ConeRefitAll(benchmark::State& state) {
  product_refit_bench(state, true, 0);
}

void args(benchmark::internal::Benchmark* b) {
  for (int garment : {0, 1}) {
    for (int build : {0, 1}) {
      for (int threads : {1, 2})
        b->Args({garment, build, threads});
    }
  }
  b->ArgNames({"garment", "patch", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
}

}  // namespace

BENCHMARK(BM_OptimalRefit)->Name("optimal_refit")->Apply(args);
BENCHMARK(BM_ProposedRefit)->Name("proposed_refit")->Apply(args);
BENCHMARK(BM_BoxRefit)->Name("box_refit")->Apply(args);
BENCHMARK(BM_ConeRefit16)->Name("cone_refit_min16")->Apply(args);
BENCHMARK(BM_ConeRefitAll)->Name("cone_refit_all")->Apply(args);
BENCHMARK_MAIN();
