// ns per cone merge, per CCD leaf cone (each policy) and per optimal cone. Inputs are prepared
// outside the timed loops, and each benchmark first checks its results against a reference
// property (containment / ordering) before timing.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "clothcd/geometry/angle.hpp"
#include "clothcd/geometry/cone.hpp"

namespace {

using clothcd::NormalCone;
using Eigen::Vector3d;

constexpr std::size_t kInputs = 4096;  // power of two: index with a mask

struct Sampler {
  std::mt19937_64 gen{2021};
  double uniform() { return static_cast<double>(gen() >> 11) * 0x1.0p-53; }
  Vector3d unit() {
    const double z = 2 * uniform() - 1, phi = 2 * std::numbers::pi * uniform();
    const double r = std::sqrt(1 - z * z);
    return {r * std::cos(phi), r * std::sin(phi), z};
  }
};

// Cone pairs at scales log-uniform in [1e-6, 0.5] rad (mostly unsaturated merges).
std::vector<std::pair<NormalCone, NormalCone>> cone_pairs() {
  Sampler s;
  std::vector<std::pair<NormalCone, NormalCone>> out;
  for (std::size_t i = 0; i < kInputs; ++i) {
    const double scale = std::exp(std::log(1e-6) + s.uniform() * (std::log(0.5) - std::log(1e-6)));
    const Vector3d a = s.unit();
    const Vector3d b = (a + scale * s.unit()).normalized();
    out.push_back({{a, scale * s.uniform()}, {b, scale * s.uniform()}});
  }
  return out;
}

struct Moving {
  std::array<Vector3d, 6> v;
};

// Unit-size triangles moving by 10% of their size.
std::vector<Moving> moving_triangles() {
  Sampler s;
  std::vector<Moving> out;
  for (std::size_t i = 0; i < kInputs; ++i) {
    Moving m;
    for (int k = 0; k < 3; ++k)
      m.v[k] = s.unit();
    for (int k = 0; k < 3; ++k)
      m.v[k + 3] = m.v[k] + 0.1 * s.unit();
    out.push_back(m);
  }
  return out;
}

void check(bool ok, const char* what) {
  if (!ok) throw std::runtime_error(what);
}

template <NormalCone (*Merge)(const NormalCone&, const NormalCone&)>
void BM_Merge(benchmark::State& state) {
  const auto pairs = cone_pairs();
  for (const auto& [a, b] : pairs) {
    const NormalCone m = Merge(a, b);
    check(clothcd::contains(m, a, 1e-12) && clothcd::contains(m, b, 1e-12),
          "merge does not contain its inputs");
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& [a, b] = pairs[i];
    benchmark::DoNotOptimize(Merge(a, b));
    i = (i + 1) & (kInputs - 1);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Merge<clothcd::merge_provot>)->Name("merge_provot");
BENCHMARK(BM_Merge<clothcd::merge_tight>)->Name("merge_tight");

void BM_LeafCone(benchmark::State& state) {
  const auto policy = static_cast<clothcd::LeafConePolicy>(state.range(0));
  const auto tris = moving_triangles();
  double sum = 0;
  int saturated = 0;
  for (const auto& m : tris) {
    const auto leaf = [&](clothcd::LeafConePolicy p) {
      return clothcd::ccd_leaf_cone(m.v[0], m.v[1], m.v[2], m.v[3], m.v[4], m.v[5], p);
    };
    const double exact = leaf(clothcd::LeafConePolicy::Exact).half_angle;
    const double proposed = leaf(clothcd::LeafConePolicy::Proposed).half_angle;
    const double tang = leaf(clothcd::LeafConePolicy::Tang).half_angle;
    check(exact <= proposed + 1e-11 && proposed <= tang + 1e-11, "Exact <= Proposed <= Tang");
    const NormalCone c = leaf(policy);
    sum += c.half_angle;
    saturated += c.saturated() ? 1 : 0;
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& m = tris[i];
    benchmark::DoNotOptimize(
        clothcd::ccd_leaf_cone(m.v[0], m.v[1], m.v[2], m.v[3], m.v[4], m.v[5], policy));
    i = (i + 1) & (kInputs - 1);
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["mean_deg"] = sum / tris.size() * 180 / std::numbers::pi;
  state.counters["saturated"] = saturated;
}
BENCHMARK(BM_LeafCone)->Name("ccd_leaf_cone/Tang")->Arg(0);
BENCHMARK(BM_LeafCone)->Name("ccd_leaf_cone/Proposed")->Arg(1);
BENCHMARK(BM_LeafCone)->Name("ccd_leaf_cone/Exact")->Arg(2);

void BM_OptimalCone(benchmark::State& state) {
  Sampler s;
  const auto n = static_cast<std::size_t>(state.range(0));
  const Vector3d centre = s.unit();
  std::vector<Vector3d> v;
  for (std::size_t i = 0; i < n; ++i)
    v.push_back((centre + 0.5 * s.unit()).normalized());
  const NormalCone c = clothcd::optimal_cone(v);
  for (const auto& p : v)
    check(clothcd::contains(c, p), "optimal cone misses an input");
  for (auto _ : state)
    benchmark::DoNotOptimize(clothcd::optimal_cone(v));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
  state.counters["half_angle_deg"] = c.half_angle * 180 / std::numbers::pi;
}
BENCHMARK(BM_OptimalCone)
    ->Name("optimal_cone")
    ->Arg(100)
    ->Arg(10000)
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
