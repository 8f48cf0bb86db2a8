// `clothcd demo`: a real continuous collision detection step on a procedural scene (no data
// needed), every culling mode and cone policy side by side; `clothcd demo --cones` prints the
// comparison of the normal-cone merges on random data instead.
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include <chrono>
#include <optional>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/names.hpp"
#include "clothcd/geometry/cone.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"
#include "clothcd/research/procedural.hpp"
#include "command.hpp"
#include "misses.hpp"

namespace clothcd::app {
namespace {

using Eigen::Vector3d;

constexpr double kDeg = 180.0 / std::numbers::pi;

// Portable seeded sampling (our own conversion, so the output is the same on every platform).
struct Sampler {
  std::mt19937_64 gen;
  double uniform() { return static_cast<double>(gen() >> 11) * 0x1.0p-53; }
  double log_uniform(double lo, double hi) {
    return std::exp(std::log(lo) + uniform() * (std::log(hi) - std::log(lo)));
  }
  Vector3d unit() {
    const double z = 2 * uniform() - 1, phi = 2 * std::numbers::pi * uniform();
    const double r = std::sqrt(1 - z * z);
    return {r * std::cos(phi), r * std::sin(phi), z};
  }
};

// Mean half-angle (degrees, saturated cones counted at 90) and saturated count.
struct Tally {
  double sum = 0;
  double sum_unsaturated = 0;
  long saturated = 0;
  long count = 0;
  void add(const NormalCone& c) {
    ++count;
    sum += c.half_angle;
    if (c.saturated()) {
      ++saturated;
    } else {
      sum_unsaturated += c.half_angle;
    }
  }
  [[nodiscard]] double mean_deg() const { return count ? sum / count * kDeg : 0.0; }
  [[nodiscard]] double mean_unsaturated_deg() const {
    return count > saturated ? sum_unsaturated / (count - saturated) * kDeg : 0.0;
  }
  [[nodiscard]] double saturated_pct() const { return count ? 100.0 * saturated / count : 0.0; }
};

void print_row(const char* name, const Tally& t) {
  fmt::print("  {:<10} {:>12.4f} {:>18.4f} {:>11} {:>10.2f}\n", name, t.mean_deg(),
             t.mean_unsaturated_deg(), t.saturated, t.saturated_pct());
}

void print_header(const char* first) {
  fmt::print("  {:<10} {:>12} {:>18} {:>11} {:>10}\n", first, "mean(deg)", "mean unsat.(deg)",
             "saturated", "% sat.");
}

// 1. Random cone pairs: the binary merges side by side (the tight merge is the optimal cone of
// two cones, so it is the OPTIMAL column here).
void compare_pairs(Sampler& s, int count) {
  Tally provot, tight;
  for (int i = 0; i < count; ++i) {
    const double scale = s.log_uniform(1e-6, 1.0);
    const Vector3d a = s.unit();
    const Vector3d b = (a + scale * 2 * s.uniform() * s.unit()).normalized();
    const NormalCone ca{a, scale * s.uniform()}, cb{b, scale * s.uniform()};
    provot.add(merge_provot(ca, cb));
    tight.add(merge_tight(ca, cb));
  }
  fmt::print("Random cone pairs ({} pairs, scales 1e-6..1 rad):\n", count);
  print_header("merge");
  print_row("PROVOT", provot);
  print_row("PROPOSED", tight);
}

// 2. Hierarchical merges over the triangle normals of a noisy wavy sheet: a binary hierarchy by
// recursive halving of the grid; each node's cone by PROVOT and PROPOSED merges of its children,
// and OPTIMAL from all its descendant normals.
void compare_hierarchy(Sampler& s) {
  constexpr int kGrid = 64;  // 64 x 64 quads, 8192 triangles
  std::vector<Vector3d> pos((kGrid + 1) * (kGrid + 1));
  for (int j = 0; j <= kGrid; ++j) {
    for (int i = 0; i <= kGrid; ++i) {
      const double x = static_cast<double>(i) / kGrid, y = static_cast<double>(j) / kGrid;
      const double z = 0.05 * std::sin(6 * x) * std::sin(5 * y) + 0.002 * (s.uniform() - 0.5);
      pos[j * (kGrid + 1) + i] = {x, y, z};
    }
  }
  // Normals of the two triangles of quad (i, j), stored per quad cell.
  std::vector<std::array<Vector3d, 2>> quad_normals(kGrid * kGrid);
  for (int j = 0; j < kGrid; ++j) {
    for (int i = 0; i < kGrid; ++i) {
      const Vector3d& p00 = pos[j * (kGrid + 1) + i];
      const Vector3d& p10 = pos[j * (kGrid + 1) + i + 1];
      const Vector3d& p01 = pos[(j + 1) * (kGrid + 1) + i];
      const Vector3d& p11 = pos[(j + 1) * (kGrid + 1) + i + 1];
      quad_normals[j * kGrid + i] = {(p10 - p00).cross(p11 - p00).normalized(),
                                     (p11 - p00).cross(p01 - p00).normalized()};
    }
  }
  struct NodeCones {
    NormalCone provot, tight;
  };
  constexpr int kMaxDepth = 13;
  std::array<Tally, kMaxDepth + 1> provot, tight, optimal;
  std::vector<Vector3d> normals;
  // Returns the node's cones; a node covers quads [i0, i1) x [j0, j1).
  auto build = [&](auto&& self, int i0, int i1, int j0, int j1, int depth) -> NodeCones {
    if (i1 - i0 == 1 && j1 - j0 == 1) {
      const auto& n = quad_normals[j0 * kGrid + i0];
      const NormalCone a{n[0], 0.0}, b{n[1], 0.0};
      const NodeCones c{merge_provot(a, b), merge_tight(a, b)};
      normals = {n[0], n[1]};
      optimal[depth].add(optimal_cone(normals));
      provot[depth].add(c.provot);
      tight[depth].add(c.tight);
      return c;
    }
    NodeCones left, right;
    if (i1 - i0 >= j1 - j0) {
      const int mid = (i0 + i1) / 2;
      left = self(self, i0, mid, j0, j1, depth + 1);
      right = self(self, mid, i1, j0, j1, depth + 1);
    } else {
      const int mid = (j0 + j1) / 2;
      left = self(self, i0, i1, j0, mid, depth + 1);
      right = self(self, i0, i1, mid, j1, depth + 1);
    }
    const NodeCones c{merge_provot(left.provot, right.provot),
                      merge_tight(left.tight, right.tight)};
    normals.clear();
    for (int j = j0; j < j1; ++j) {
      for (int i = i0; i < i1; ++i) {
        normals.push_back(quad_normals[j * kGrid + i][0]);
        normals.push_back(quad_normals[j * kGrid + i][1]);
      }
    }
    optimal[depth].add(optimal_cone(normals));
    provot[depth].add(c.provot);
    tight[depth].add(c.tight);
    return c;
  };
  build(build, 0, kGrid, 0, kGrid, 0);
  fmt::print(
      "\nHierarchical merges over a noisy wavy sheet ({} triangles), mean half-angle (deg) "
      "per depth:\n",
      2 * kGrid * kGrid);
  fmt::print("  {:>5} {:>6} {:>10} {:>10} {:>10} {:>12} {:>10}\n", "depth", "nodes", "PROVOT",
             "PROPOSED", "OPTIMAL", "PROP/OPT", "% sat P/T");
  for (int d = 0; d <= kMaxDepth - 1; ++d) {
    if (optimal[d].count == 0) continue;
    fmt::print("  {:>5} {:>6} {:>10.4f} {:>10.4f} {:>10.4f} {:>12.3f} {:>5.1f}/{:<4.1f}\n", d,
               optimal[d].count, provot[d].mean_deg(), tight[d].mean_deg(), optimal[d].mean_deg(),
               optimal[d].mean_deg() > 0 ? tight[d].mean_deg() / optimal[d].mean_deg() : 1.0,
               provot[d].saturated_pct(), tight[d].saturated_pct());
  }
}

// 3. CCD leaf cones of random moving triangles: vertices in the unit cube, each displaced by a
// random vector of length `motion` times the triangle's mean edge length.
void compare_leaf_cones(Sampler& s, int count, double motion) {
  std::array<Tally, 3> tally;
  constexpr std::array kPolicies = {LeafConePolicy::Tang, LeafConePolicy::Proposed,
                                    LeafConePolicy::Exact};
  for (int i = 0; i < count; ++i) {
    std::array<Vector3d, 3> t0, t1;
    for (auto& p : t0)
      p = {s.uniform(), s.uniform(), s.uniform()};
    const double edge =
        ((t0[1] - t0[0]).norm() + (t0[2] - t0[1]).norm() + (t0[0] - t0[2]).norm()) / 3;
    for (int k = 0; k < 3; ++k)
      t1[k] = t0[k] + motion * edge * s.unit();
    for (std::size_t p = 0; p < kPolicies.size(); ++p) {
      tally[p].add(ccd_leaf_cone(t0[0], t0[1], t0[2], t1[0], t1[1], t1[2], kPolicies[p]));
    }
  }
  fmt::print(
      "\nCCD leaf cones of {} random moving triangles, vertex motion {:.0f}% of the mean edge:\n",
      count, motion * 100);
  print_header("policy");
  print_row("TANG", tally[0]);
  print_row("PROPOSED", tally[1]);
  print_row("EXACT", tally[2]);
}

}  // namespace

/// Prints the cone-merge comparison: random pairs, a hierarchy over a wavy sheet, and the leaf
/// cone statistics at small (10%) and large (100%) motion. Deterministic for a seed.
void print_cone_comparison(std::uint64_t seed, int count) {
  if (count <= 0) throw InputError(fmt::format("demo: --count must be positive, got {}", count));
  Sampler s{std::mt19937_64(seed)};
  fmt::print("clothcd demo: normal-cone merges (seed {}, count {})\n\n", seed, count);
  compare_pairs(s, count);
  compare_hierarchy(s);
  compare_leaf_cones(s, count, 0.1);
  compare_leaf_cones(s, count, 1.0);
}

namespace {

using cli::missed_against;

struct DemoArgs {
  std::string scene = "crumpled";
  int size = 0;  // 0: the scene's default (about 30K triangles)
  std::uint64_t seed = 1;
  std::string bvh = "patch";
  int threads = 0;
  bool cones = false;
  int count = 100000;
  double from = 0.6, to = 0.65;  // the step: this part of the scene's motion
};

research::ProceduralScene demo_scene(const DemoArgs& a) {
  if (a.size < 0) throw InputError(fmt::format("demo: --size must be >= 0, got {}", a.size));
  if (!(0 <= a.from && a.from < a.to && a.to <= 1)) {
    throw InputError(
        fmt::format("demo: need 0 <= --from < --to <= 1, got {} and {}", a.from, a.to));
  }
  research::ProceduralScene s;
  if (a.scene == "crumpled") {
    s = research::crumpled_sheet(a.size > 0 ? a.size : 120, a.seed);
  } else if (a.scene == "twisted") {
    const int n = a.size > 0 ? a.size : 800;
    s = research::twisted_strip(n, std::max(2, n / 40));
  } else {
    throw InputError(fmt::format("demo: unknown --scene '{}' (crumpled|twisted)", a.scene));
  }
  // The scenes move in one large linear step; a simulator's step is a small part of such a
  // motion, taken here from the middle, where the surface is already folded.
  const Positions d = s.v_t1 - s.v_t0;
  const Positions start = s.v_t0;
  s.v_t0 = start + a.from * d;
  s.v_t1 = start + a.to * d;
  return s;
}

// One CCD step of a procedural scene through every culling mode and cone policy.
int run_detection_demo(const DemoArgs& a) {
  const BvhBuild build = parse_bvh_build(a.bvh, "demo: --bvh");
  std::optional<tbb::global_control> threads;
  if (a.threads > 0) {
    threads.emplace(tbb::global_control::max_allowed_parallelism,
                    static_cast<std::size_t>(a.threads));
  }
  const research::ProceduralScene s = demo_scene(a);
  research::DetectOptions o;
  o.build = build;
  const auto t = std::chrono::steady_clock::now();
  research::SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
  const double build_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  const Bvh& bvh = det.bvh();
  fmt::print(
      "clothcd demo: continuous self-collision detection over one step of a procedural scene\n"
      "scene {} (seed {}): {} vertices, {} triangles; {} BVH built in {:.3f} s, {:.1f}% of its "
      "internal nodes edge-connected, {:.1f}% disks\n\n",
      s.name, a.seed, s.num_vertices, s.faces.size(), a.bvh, build_s,
      100.0 * bvh.num_connected_internal() / std::max(1, bvh.num_internal()),
      100.0 * bvh.num_disk_internal() / std::max(1, bvh.num_internal()));
  const DetectResult none = det.detect(s.v_t0, s.v_t1);
  fmt::print("{:<8} {:<9} {:>12} {:>8} {:>8} {:>10} {:>10} {:>10} {:>7} {:>8}  {}\n", "culling",
             "policy", "tri. pairs", "culled", "nodes", "VF tests", "EE tests", "collisions",
             "missed", "contour", "time refit/traverse/narrow (s)");
  auto row = [&](const char* culling, const char* policy, const DetectResult& r) {
    const DetectStats& st = r.stats;
    const double culled =
        100.0 * (1.0 - double(st.triangle_pairs) /
                           std::max<double>(1.0, double(none.stats.triangle_pairs)));
    fmt::print(
        "{:<8} {:<9} {:>12} {:>7.1f}% {:>8} {:>10} {:>10} {:>10} {:>7} {:>8}  "
        "{:.3f} / {:.3f} / {:.3f}\n",
        culling, policy, st.triangle_pairs, culled, st.nodes_culled, st.vf_tests, st.ee_tests,
        r.vf.size() + r.ee.size(), missed_against(none, r),
        fmt::format("{}/{}", st.contour_tests - st.contour_fails, st.contour_tests), st.time_refit,
        st.time_traverse, st.time_narrow);
  };
  row("none", "-", none);
  using research::CullingRule;
  const std::pair<const char*, CullingRule> modes[] = {
      {"cone", CullingRule::Cone}, {"gated", CullingRule::Gated}, {"sound", CullingRule::Sound}};
  const std::pair<const char*, ConePolicy> policies[] = {{"PROVOT", ConePolicy::Provot},
                                                         {"PROPOSED", ConePolicy::Proposed},
                                                         {"EXACT", ConePolicy::Exact}};
  for (const auto& [mname, mode] : modes) {
    for (const auto& [pname, policy] : policies) {
      research::set_culling_rule(o, mode);
      o.policy = policy;
      det.set_options(o);
      row(mname, pname, det.detect(s.v_t0, s.v_t1));
    }
  }
  fmt::print(
      "\nculled: share of the unculled run's triangle pairs removed; nodes: self tests skipped by "
      "the cones;\nmissed: collisions the unculled run finds and this run does not (cone and "
      "gated are unsound,\nsound must show 0); contour: contour tests passed / run (sound only). "
      "Cone merges: clothcd demo --cones\n");
  return 0;
}

const bool registered = register_command(
    "demo",
    "One collision detection step on a procedural scene, every culling mode and cone policy "
    "(--cones: compare the normal-cone merges on random data)",
    [](CLI::App& sub) -> std::function<int()> {
      auto a = std::make_shared<DemoArgs>();
      sub.add_option("--scene", a->scene, "procedural scene: crumpled|twisted");
      sub.add_option("--size", a->size,
                     "crumpled: grid cells per side (120); twisted: segments (800)");
      sub.add_option("--bvh", a->bvh, "BVH build: spatial|patch");
      sub.add_option("--from", a->from, "the step starts at this part of the scene's motion (0.6)");
      sub.add_option("--to", a->to, "... and ends at this part (0.65)");
      sub.add_option("--threads", a->threads, "worker threads (0: all)");
      sub.add_flag("--cones", a->cones, "print the cone-merge comparison instead");
      sub.add_option("--seed", a->seed, "Random seed (the output is deterministic for a seed)");
      sub.add_option("--count", a->count,
                     "--cones: random cone pairs and moving triangles per table");
      return [a] {
        if (a->cones) {
          print_cone_comparison(a->seed, a->count);
          return 0;
        }
        return run_detection_demo(*a);
      };
    });
}  // namespace

}  // namespace clothcd::app
