// PCG iterations of the cloth solve on 2 threads: two 120 x 120 grids 1 mm apart (29,282
// vertices, the multilayer's size) stretched by 1%, with and without contact couplings between
// them (each upper vertex against the lower face under it, as when two layers rest on each
// other). A fixed 100 iterations, so the time is per iteration x 100.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <vector>

#include "clothcd/sim/cloth_model.hpp"
#include "clothcd/sim/collision.hpp"
#include "sim/couplings.hpp"
#include "sim/pcg.hpp"
#include "sim/system.hpp"

namespace {

using namespace clothcd;
using namespace clothcd::sim;

ClothMeshInput two_layers(int nx) {
  ClothMeshInput in;
  for (int layer = 0; layer < 2; ++layer) {
    const int base = static_cast<int>(in.positions.size());
    for (int j = 0; j <= nx; ++j) {
      for (int i = 0; i <= nx; ++i)
        in.positions.emplace_back(1.0 * i / nx, 1e-3 * layer, 1.0 * j / nx);
    }
    for (int j = 0; j < nx; ++j) {
      for (int i = 0; i < nx; ++i) {
        const int a = base + j * (nx + 1) + i;
        in.faces.push_back({a, a + nx + 2, a + 1});
        in.faces.push_back({a, a + nx + 1, a + nx + 2});
      }
    }
  }
  return in;
}

void BM_PcgIterations(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  const int nx = 120;  // two layers of 14,641 vertices
  const ClothModel model(two_layers(nx), ClothMaterial{});
  const int n = model.num_vertices();
  // Stretch the layers a little so that the membrane Hessian is not the rest one.
  std::vector<Vec3> x = model.initial_positions();
  for (Vec3& p : x)
    p.x() *= 1.01;
  SystemAssembler assembler(model);
  BlockCsr h = assembler.make_matrix();
  Vecs gradient;
  assembler.assemble(x, h, gradient);
  std::vector<double> inverse_mass(n);
  for (int i = 0; i < n; ++i)
    inverse_mass[i] = 1.0 / model.mass()[i];
  CouplingTerms couplings;
  if (state.range(0) != 0) {
    // Each upper-layer vertex against the lower face below it.
    std::vector<ContactCoupling> list;
    const int half = n / 2;
    for (int j = 0; j < nx; ++j) {
      for (int i = 0; i < nx; ++i) {
        ContactCoupling c;
        const int a = j * (nx + 1) + i;
        c.vertex = {half + a, a, a + nx + 2, a + 1};
        c.c = {1.0, -1.0 / 3, -1.0 / 3, -1.0 / 3};
        c.n = Vec3::UnitY();
        list.push_back(c);
      }
    }
    couplings.reset(list, inverse_mass, 100.0);
  }
  VertexFilter filter;
  filter.reset(n);
  Vecs b(n);
  for (int i = 0; i < n; ++i)
    b[i] = -0.01 * gradient[i] + Vec3(0, -1e-4, 0);
  const PcgOptions options{100, 0.0};  // always the full 100 iterations
  int iterations = 0;
  for (auto _ : state) {
    Vecs dv(n, Vec3::Zero());
    const PcgResult r = solve_pcg(h, 0.01 * 0.011, model.mass(), b, filter, options, dv,
                                  couplings.empty() ? nullptr : &couplings);
    iterations = r.iterations;
    benchmark::DoNotOptimize(dv.data());
  }
  state.counters["iterations"] = iterations;
  state.counters["vertices"] = n;
}
BENCHMARK(BM_PcgIterations)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("couplings")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
