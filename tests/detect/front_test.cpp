// DetectOptions::reuse_front: a traversal started from the last call's front finds exactly the
// leaf pairs of a traversal from the root, call after call, as the mesh moves apart and together;
// a detector using it returns the same collisions and counters (box tests aside) as one without,
// around restricted calls, proximity queries, rebuilds and option changes; and the front shrinks
// back where the boxes move apart.

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <random>
#include <vector>

#include "api_scenes.hpp"
#include "bvh/front.hpp"
#include "clothcd/bvh/bvh.hpp"
#include "clothcd/bvh/traverse.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/topology.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd {
namespace {

using Pairs = std::vector<std::pair<int, int>>;

// Steps (t0, t1) of a scene: its step in six substeps (each frame slightly perturbed, as a
// simulator's are), then a still step with everything spread out 30-fold about the first vertex
// (most boxes apart), then the last substep again.
std::vector<std::pair<Positions, Positions>> front_steps(const research::ProceduralScene& s) {
  std::vector<Positions> f;
  for (int i = 0; i <= 6; ++i) {
    const double t = i / 6.0;
    f.push_back(research::smooth_perturbation((1 - t) * s.v_t0 + t * s.v_t1, 0.003, 0.5, 7 + i));
  }
  std::vector<std::pair<Positions, Positions>> out;
  for (int i = 0; i < 6; ++i)
    out.emplace_back(f[i], f[i + 1]);
  Positions spread = f[6];
  for (Eigen::Index i = 0; i < spread.rows(); ++i)
    spread.row(i) = f[6].row(0) + 30.0 * (f[6].row(i) - f[6].row(0));
  out.emplace_back(spread, spread);
  out.emplace_back(f[5], f[6]);
  return out;
}

std::vector<research::ProceduralScene> front_scenes() {
  return {research::crumpled_sheet(10, 3), research::twisted_strip(40, 3),
          research::stacked_sheets(5), research::winding_strip(48, 2)};
}

std::vector<Eigen::Vector3d> points(const Positions& p) {
  std::vector<Eigen::Vector3d> out(static_cast<std::size_t>(p.rows()));
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    out[static_cast<std::size_t>(i)] = p.row(i).transpose();
  return out;
}

// The front's leaf pairs of one run (face ids, sorted) and its box tests.
struct FrontRun {
  Pairs pairs;
  std::uint64_t tests = 0;
};

// `live(n)`: whether internal node n's children pair is traversed this run.
FrontRun run_front(
    detail::TraversalFront& front, const Bvh& bvh,
    const std::function<bool(int)>& live = [](int) { return true; }) {
  const auto& nodes = bvh.nodes();
  if (front.empty()) {
    std::vector<detail::TraversalFront::Root> roots;
    for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
      if (!nodes[i].is_leaf()) roots.push_back({i, nodes[i].left, nodes[i].left + 1});
    }
    front.seed(roots);
  }
  tbb::enumerable_thread_specific<Pairs> locals;
  const auto& prims = bvh.prim_ids();
  FrontRun r;
  r.tests = front.run(
      bvh, bvh, live,
      [&](int a, int b, Pairs& out) {
        out.emplace_back(prims[nodes[a].first], prims[nodes[b].first]);
      },
      locals);
  for (const Pairs& l : locals)
    r.pairs.insert(r.pairs.end(), l.begin(), l.end());
  std::sort(r.pairs.begin(), r.pairs.end());
  return r;
}

TEST(TraversalFront, SameLeafPairsAsTheFullTraversal) {
  for (const auto& s : front_scenes()) {
    const Topology topo(s.faces, s.num_vertices);
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      Bvh bvh(topo, points(s.v_t0), build);
      detail::TraversalFront front;
      const auto steps = front_steps(s);
      std::size_t stops_before_spread = 0;
      for (std::size_t k = 0; k < steps.size(); ++k) {
        bvh.refit(points(steps[k].first), points(steps[k].second), RefitOptions{});
        Pairs ref = overlapping_leaf_pairs(bvh);
        std::sort(ref.begin(), ref.end());
        const FrontRun a = run_front(front, bvh);
        EXPECT_EQ(a.pairs, ref) << s.name << " step " << k;
        // A second run on the same boxes: the same pairs and front; each front pair tested once,
        // and the pair above two missing siblings whose merge it prevents.
        const std::size_t size = front.size();
        const FrontRun b = run_front(front, bvh);
        EXPECT_EQ(b.pairs, ref) << s.name << " step " << k;
        EXPECT_GE(b.tests, size) << s.name << " step " << k;
        EXPECT_LE(b.tests, size + size / 2) << s.name << " step " << k;
        EXPECT_EQ(front.size(), size) << s.name << " step " << k;
        if (k == 5) stops_before_spread = front.size();
        // Where the boxes moved apart, the front is what a fresh one ends as: the misses merged
        // back up to the first missing pair below each root.
        detail::TraversalFront fresh;
        run_front(fresh, bvh);
        EXPECT_EQ(front.size(), fresh.size()) << s.name << " step " << k;
      }
      EXPECT_GT(stops_before_spread, 0u);
    }
  }
}

// The overlapping leaf pairs (faces, sorted) of the children pairs of the internal nodes with
// live(n), by testing every leaf of one child against every leaf of the other.
Pairs brute_force_leaf_pairs(const Bvh& bvh, const std::function<bool(int)>& live) {
  const auto& nodes = bvh.nodes();
  const auto& prims = bvh.prim_ids();
  Pairs out;
  for (int n = 0; n < static_cast<int>(nodes.size()); ++n) {
    if (nodes[n].is_leaf() || !live(n)) continue;
    const BvhNode& l = nodes[nodes[n].left];
    const BvhNode& r = nodes[nodes[n].left + 1];
    for (int i = l.first; i < l.first + l.count; ++i) {
      for (int j = r.first; j < r.first + r.count; ++j) {
        const int fa = prims[i], fb = prims[j];
        if (overlap(nodes[bvh.leaf_of_face(fa)], nodes[bvh.leaf_of_face(fb)])) {
          out.emplace_back(fa, fb);
        }
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Roots left out of a run (as a culled node's are) go back to their children pair; the roots
// traversed give exactly the overlapping leaf pairs below them, whatever was left out before;
// also with every root's front cut into pieces of 3 pairs (several segments per root).
TEST(TraversalFront, RootsLeftOutStartAgainFromTheirChildrenPair) {
  for (const auto& s : front_scenes()) {
    for (std::uint32_t piece : {4096u, 3u}) {
      const Topology topo(s.faces, s.num_vertices);
      Bvh bvh(topo, points(s.v_t0), BvhBuild::Patch);
      detail::TraversalFront front(piece);
      std::mt19937 rng(5);
      const auto steps = front_steps(s);
      for (std::size_t k = 0; k < steps.size(); ++k) {
        bvh.refit(points(steps[k].first), points(steps[k].second), RefitOptions{});
        // Each internal node traversed with probability 0.6 (every one at the last step).
        std::vector<std::uint8_t> on(bvh.nodes().size());
        for (auto& x : on)
          x = k + 1 == steps.size() || rng() % 5 < 3;
        const auto live = [&](int n) { return on[n] != 0; };
        const FrontRun a = run_front(front, bvh, live);
        EXPECT_EQ(a.pairs, brute_force_leaf_pairs(bvh, live)) << s.name << " step " << k;
        EXPECT_GT(a.pairs.size(), 0u) << s.name << " piece " << piece << " step " << k;
      }
      Pairs all = overlapping_leaf_pairs(bvh);
      std::sort(all.begin(), all.end());
      EXPECT_EQ(run_front(front, bvh).pairs, all) << s.name;
    }
  }
}

// Every counter of a detection but the box tests and the front's size.
void expect_same_as_without_front(const DetectResult& r, const DetectResult& ref,
                                  const std::string& what) {
  EXPECT_EQ(r.vf, ref.vf) << what;
  EXPECT_EQ(r.ee, ref.ee) << what;
  const DetectStats& a = r.stats;
  const DetectStats& b = ref.stats;
  EXPECT_EQ(a.triangle_pairs, b.triangle_pairs) << what;
  EXPECT_EQ(a.adjacent_pairs, b.adjacent_pairs) << what;
  EXPECT_EQ(a.nodes_culled, b.nodes_culled) << what;
  EXPECT_EQ(a.cone_tests, b.cone_tests) << what;
  EXPECT_EQ(a.contour_tests, b.contour_tests) << what;
  EXPECT_EQ(a.contour_fails, b.contour_fails) << what;
  EXPECT_EQ(a.vf_tests, b.vf_tests) << what;
  EXPECT_EQ(a.ee_tests, b.ee_tests) << what;
  EXPECT_EQ(a.vf_np_culled, b.vf_np_culled) << what;
  EXPECT_EQ(a.ee_np_culled, b.ee_np_culled) << what;
  EXPECT_EQ(a.triangle_pairs_apart, b.triangle_pairs_apart) << what;
}

TEST(ReuseFront, DetectorResultsUnchanged) {
  for (const auto& s : front_scenes()) {
    const double scale = (s.v_t0.colwise().maxCoeff() - s.v_t0.colwise().minCoeff()).norm();
    for (Culling culling : {Culling::None, Culling::Sound}) {
      for (double thickness : {0.0, 0.001 * scale}) {
        {
          // The simulator's build with its culling; the median splits without.
          const BvhBuild build = culling == Culling::Sound ? BvhBuild::Patch : BvhBuild::Spatial;
          DetectOptions plain;
          plain.culling = culling;
          plain.thickness = thickness;
          plain.build = build;
          plain.reuse_distance = thickness;  // a simulator's setting (0: off)
          DetectOptions o = plain;
          o.reuse_front = true;
          SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
          SelfDetector ref(s.faces, s.num_vertices, s.v_t0, plain);
          const auto steps = front_steps(s);
          std::uint64_t tests = 0, ref_tests = 0;  // of the substeps from an existing front
          for (std::size_t k = 0; k < steps.size(); ++k) {
            const Positions& x0 = steps[k].first;
            const Positions& x1 = steps[k].second;
            const std::string what = s.name + " step " + std::to_string(k) + " culling " +
                                     std::to_string(int(culling)) + " thickness " +
                                     std::to_string(thickness);
            const DetectResult a = det.detect(x0, x1);
            const DetectResult b = ref.detect(x0, x1);
            expect_same_as_without_front(a, b, what);
            EXPECT_GT(a.stats.front_pairs, 0u) << what;
            EXPECT_EQ(b.stats.front_pairs, 0u) << what;
            // A fresh front (the first call, the first after the rebuild) makes the full
            // traversal's tests.
            if (k == 0 || k == 4) {
              EXPECT_EQ(a.stats.box_tests, b.stats.box_tests) << what;
            } else if (k < 6) {
              tests += a.stats.box_tests;
              ref_tests += b.stats.box_tests;
            }
            // What a simulator does between its steps, which leaves the front alone.
            if (k == 1) {
              const std::vector<int> some = {0, 1, 2, 3};
              det.set_active_faces(some);
              ref.set_active_faces(some);
              expect_same_as_without_front(det.detect(x0, x1), ref.detect(x0, x1),
                                           what + " restricted");
              det.clear_active();
              ref.clear_active();
            }
            if (k == 2) {
              const ProximityResult pa = det.proximity(x1, thickness);
              const ProximityResult pb = ref.proximity(x1, thickness);
              EXPECT_EQ(test::vf_pairs(pa.vf), test::vf_pairs(pb.vf)) << what;
              EXPECT_EQ(test::ee_pairs(pa.ee), test::ee_pairs(pb.ee)) << what;
            }
            if (k == 3) {
              det.rebuild(x1);
              ref.rebuild(x1);
            }
          }
          // Over substeps of a slow motion the front saves box tests where the traversal has
          // many to save (without culling). The twisted strip crosses itself within the six
          // substeps: contact comes and goes faster than a front pays.
          if (culling == Culling::None && s.name.find("twisted") == std::string::npos) {
            EXPECT_LT(tests, ref_tests) << s.name;
          }
          // Turned off, the front is dropped.
          det.set_options(plain);
          EXPECT_EQ(det.detect(steps[0].first, steps[0].second).stats.front_pairs, 0u);
        }
      }
    }
  }
}

TEST(ReuseFront, PairDetectorResultsUnchanged) {
  // A ball passing through a sheet in twelve substeps, then far away and back.
  const test::Mesh a = test::sheet(10);
  const test::Mesh b = test::ball(3, 0.2, {0.45, 0.5, 0.3}, {0.55, 0.5, -0.3});
  std::vector<Positions> fa, fb;
  for (int i = 0; i <= 12; ++i) {
    const double t = i / 12.0;
    fa.push_back((1 - t) * a.v0 + t * a.v1);
    fb.push_back((1 - t) * b.v0 + t * b.v1);
  }
  fa.push_back(fa.back());
  fb.push_back(fb.back().rowwise() + Eigen::RowVector3d(0, 0, 5));
  fa.push_back(fa[12]);
  fb.push_back(fb[12]);
  for (double thickness : {0.0, 0.01}) {
    DetectOptions plain;
    plain.thickness = thickness;
    DetectOptions o = plain;
    o.reuse_front = true;
    PairDetector det(a.faces, a.nv(), a.v0, b.faces, b.nv(), b.v0, o);
    PairDetector ref(a.faces, a.nv(), a.v0, b.faces, b.nv(), b.v0, plain);
    std::uint64_t tests = 0, ref_tests = 0;
    for (std::size_t k = 0; k + 1 < fa.size(); ++k) {
      SCOPED_TRACE(::testing::Message() << "thickness " << thickness << " step " << k);
      const PairDetectResult r = det.detect(fa[k], fa[k + 1], fb[k], fb[k + 1]);
      const PairDetectResult r0 = ref.detect(fa[k], fa[k + 1], fb[k], fb[k + 1]);
      test::expect_pair_equal(r, r0);
      EXPECT_EQ(r.stats.triangle_pairs, r0.stats.triangle_pairs);
      EXPECT_GT(r.stats.front_pairs, 0u);
      if (k == 0) {
        EXPECT_EQ(r.stats.box_tests, r0.stats.box_tests);
      }
      if (k > 0 && k < 12) {
        tests += r.stats.box_tests;
        ref_tests += r0.stats.box_tests;
      }
      if (k == 3) {  // a proximity query and a rebuild leave the results alone
        const PairProximityResult p = det.proximity(fa[k + 1], fb[k + 1], 0.02);
        const PairProximityResult p0 = ref.proximity(fa[k + 1], fb[k + 1], 0.02);
        EXPECT_EQ(test::vf_pairs(p.vf_a_on_b), test::vf_pairs(p0.vf_a_on_b));
        EXPECT_EQ(test::ee_pairs(p.ee), test::ee_pairs(p0.ee));
        det.rebuild(fa[k + 1], fb[k + 1]);
        ref.rebuild(fa[k + 1], fb[k + 1]);
      }
    }
    EXPECT_LT(tests, ref_tests);
  }
}

}  // namespace
}  // namespace clothcd
