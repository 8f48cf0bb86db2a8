// The detector API against brute force on small scenes: two-mesh detection (a sheet and a closed
// box-like mesh moving through it), proximity queries against an all-feature-pairs distance oracle,
// active-face restriction; and determinism of results and counters on 1, 2 and 4 threads, for self
// and pair detection. Thickness > 0 is in api_thickness_test.cpp (label slow: thick kernels).

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <tuple>

#include "api_scenes.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"
#include "clothcd/research/oracle.hpp"
#include "clothcd/research/procedural.hpp"
#include "support/detect_stats.hpp"

namespace clothcd {
// A namespace of its own: the research types below stay in this file of the unity build.
namespace api_test {

// The research detector and options (unsound rules, optimal cones, verification).
using research::DetectOptions;
using research::SelfDetector;

using namespace clothcd::test;

TEST(DetectApi, PairDetectorEqualsBruteForce) {
  check_pair_detector(0.0);
}
TEST(DetectApi, ProximityEqualsAllPairsDistance) {
  for (const auto& s : {research::crumpled_sheet(8, 2), research::twisted_strip(30, 3),
                        research::stacked_sheets(6)}) {
    const Topology topo(s.faces, s.num_vertices);
    // A folded state (the end of the motion), where features come close.
    const Positions v = 0.5 * (s.v_t0 + s.v_t1);
    for (double h : {0.0, 0.01, 0.05}) {
      const ProximityResult ref = brute_force_proximity(topo, v, h);
      if (h > 0) {
        EXPECT_GT(ref.vf.size() + ref.ee.size(), 0u);
      }
      for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
        SCOPED_TRACE(::testing::Message() << s.name << " h " << h << " build " << int(build));
        DetectOptions o;
        o.build = build;
        o.culling = Culling::Sound;  // must be ignored: proximity never culls by cones
        SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
        const ProximityResult r = det.proximity(v, h);
        EXPECT_EQ(vf_pairs(r.vf), vf_pairs(ref.vf));
        EXPECT_EQ(ee_pairs(r.ee), ee_pairs(ref.ee));
        for (std::size_t i = 0; i < std::min(r.vf.size(), ref.vf.size()); ++i)
          EXPECT_EQ(r.vf[i].distance, ref.vf[i].distance);
      }
    }
  }
}

// A detector restricted by `restrict` finds `ref`, a strict non-empty part of `full`, and
// `full` again once the restriction is cleared; both builds, with and without culling.
template <class Restrict>
void check_restricted(const research::ProceduralScene& s, const DetectResult& full,
                      const DetectResult& ref, Restrict&& restrict) {
  EXPECT_GT(ref.vf.size() + ref.ee.size(), 0u) << s.name;
  EXPECT_LT(ref.vf.size() + ref.ee.size(), full.vf.size() + full.ee.size()) << s.name;
  for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
    for (Culling culling : {Culling::None, Culling::Sound}) {
      SCOPED_TRACE(::testing::Message()
                   << s.name << " build " << int(build) << " culling " << int(culling));
      DetectOptions o;
      o.build = build;
      o.culling = culling;
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      restrict(det);
      const DetectResult r = det.detect(s.v_t0, s.v_t1);
      EXPECT_EQ(r.vf, ref.vf);
      EXPECT_EQ(r.ee, ref.ee);
      det.clear_active();
      const DetectResult all = det.detect(s.v_t0, s.v_t1);
      EXPECT_EQ(all.vf, full.vf);
      EXPECT_EQ(all.ee, full.ee);
    }
  }
}

TEST(DetectApi, ActiveFacesEqualFilteredBruteForce) {
  for (const auto& s : {research::crumpled_sheet(8, 3), research::twisted_strip(30, 3)}) {
    const Topology topo(s.faces, s.num_vertices);
    // Every third face, and a contiguous block: both sparse and clustered sets.
    std::vector<int> active;
    std::vector<std::uint8_t> mask(topo.num_faces(), 0);
    for (int f = 0; f < topo.num_faces(); ++f) {
      if (f % 3 == 0 || (f > topo.num_faces() / 2 && f < topo.num_faces() / 2 + 20)) {
        active.push_back(f);
        mask[f] = 1;
      }
    }
    const DetectResult full = research::brute_force_detect(topo, s.v_t0, s.v_t1);
    const DetectResult ref = research::brute_force_detect(topo, s.v_t0, s.v_t1, {}, mask);
    check_restricted(s, full, ref, [&](SelfDetector& d) { d.set_active_faces(active); });
  }
}

TEST(DetectApi, ActiveVerticesEqualFilteredBruteForce) {
  for (const auto& s : {research::crumpled_sheet(8, 3), research::twisted_strip(30, 3)}) {
    const Topology topo(s.faces, s.num_vertices);
    // Every fifth vertex, and a contiguous block: both sparse and clustered sets.
    std::vector<int> active;
    std::vector<std::uint8_t> on(s.num_vertices, 0);
    for (int v = 0; v < s.num_vertices; ++v) {
      if (v % 5 == 0 || (v > s.num_vertices / 2 && v < s.num_vertices / 2 + 15)) {
        active.push_back(v);
        on[v] = 1;
      }
    }
    // The oracle: every pair of the full brute force with an active vertex.
    const DetectResult full = research::brute_force_detect(topo, s.v_t0, s.v_t1);
    DetectResult ref;
    for (const auto& c : full.vf) {
      const Face& f = c.face_vertices;
      if (on[c.vertex] || on[f[0]] || on[f[1]] || on[f[2]]) ref.vf.push_back(c);
    }
    for (const auto& c : full.ee) {
      const Edge &a = c.edge_a_vertices, &b = c.edge_b_vertices;
      if (on[a[0]] || on[a[1]] || on[b[0]] || on[b[1]]) ref.ee.push_back(c);
    }
    check_restricted(s, full, ref, [&](SelfDetector& d) { d.set_active_vertices(active); });
    SelfDetector det(s.faces, s.num_vertices, s.v_t0, {});
    const std::vector<int> bad{0, s.num_vertices};
    EXPECT_THROW(det.set_active_vertices(bad), InputError);
  }
}

// A detector reused over a sequence like the simulator's (a full pass, restricted passes in which
// some vertices change their end position, a proximity query, a new step) keeps its boxes and
// BVH from call to call where vertices did not move; every result must still equal brute force on
// that call's positions. The moved and the active vertices differ on purpose: the reuse must not
// depend on the caller's restriction.
TEST(DetectApi, ReusedDetectorEqualsBruteForceOverASequenceOfCalls) {
  for (const auto& s : {research::crumpled_sheet(8, 3), research::twisted_strip(30, 3)}) {
    const Topology topo(s.faces, s.num_vertices);
    for (Culling culling : {Culling::None, Culling::Sound}) {
      SCOPED_TRACE(::testing::Message() << s.name << " culling " << int(culling));
      DetectOptions o;
      o.culling = culling;
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      // Vertices take their end positions a few at a time, so each call has collisions that the
      // previous call's boxes would miss.
      const Positions& end = s.v_t1;
      Positions x0 = s.v_t0, x1 = s.v_t0;
      std::size_t found = 0;
      for (int call = 0; call < 8; ++call) {
        std::vector<std::uint8_t> on(s.num_vertices, 0);
        std::vector<int> active;
        for (int v = 0; v < s.num_vertices; ++v) {
          if (call >= 1 && call <= 3 && v % 3 == call - 1) x1.row(v) = end.row(v);
          if (call == 5 && v % 2 == 0) x1.row(v) = x0.row(v);
          if (call == 7 && v % 5 == 0) x1.row(v) = x0.row(v);
        }
        if (call == 4) {
          (void)det.proximity(x0, 0.01);  // a static refit between two detections
        }
        if (call == 6) {
          x0 = s.v_t0 + 0.5 * (end - s.v_t0);  // the next step: every vertex moves
          x1 = end;
        }
        if (call % 3 == 1) {
          for (int v = 0; v < s.num_vertices; v += 4) {
            active.push_back(v);
            on[v] = 1;
          }
          det.set_active_vertices(active);
        } else {
          det.clear_active();
        }
        const DetectResult r = det.detect(x0, x1);
        const DetectResult all = research::brute_force_detect(topo, x0, x1);
        DetectResult ref;
        for (const auto& c : all.vf) {
          const Face& f = c.face_vertices;
          if (active.empty() || on[c.vertex] || on[f[0]] || on[f[1]] || on[f[2]]) {
            ref.vf.push_back(c);
          }
        }
        for (const auto& c : all.ee) {
          const Edge &a = c.edge_a_vertices, &b = c.edge_b_vertices;
          if (active.empty() || on[a[0]] || on[a[1]] || on[b[0]] || on[b[1]]) ref.ee.push_back(c);
        }
        EXPECT_EQ(vf_pairs(r.vf), vf_pairs(ref.vf)) << "call " << call;
        EXPECT_EQ(ee_pairs(r.ee), ee_pairs(ref.ee)) << "call " << call;
        found += r.vf.size() + r.ee.size();
      }
      EXPECT_GT(found, 0u);
    }
  }
}

// rebuild(): the tree a build on the new shape gives, the same pairs as brute force before and
// after (CCD, and a proximity query that reuses the last detection's pairs), the restriction
// cleared, and a reference of the wrong size an InputError.
TEST(DetectApi, RebuiltDetectorEqualsBruteForce) {
  int changed = 0;  // cases in which the rebuilt tree differs from the original one
  for (const auto& s : {research::crumpled_sheet(8, 3), research::twisted_strip(30, 3),
                        research::stacked_sheets(6)}) {
    const Topology topo(s.faces, s.num_vertices);
    const Positions mid = 0.5 * (s.v_t0 + s.v_t1);
    const DetectResult ref0 = research::brute_force_detect(topo, s.v_t0, mid);
    const DetectResult ref1 = research::brute_force_detect(topo, mid, s.v_t1);
    const ProximityResult near = brute_force_proximity(topo, s.v_t1, 0.01);
    EXPECT_GT(ref1.vf.size() + ref1.ee.size(), 0u);
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      for (Culling culling : {Culling::None, Culling::Sound}) {
        SCOPED_TRACE(::testing::Message()
                     << s.name << " build " << int(build) << " culling " << int(culling));
        DetectOptions o;
        o.build = build;
        o.culling = culling;
        o.reuse_distance = 0.01;
        SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
        DetectResult r = det.detect(s.v_t0, mid);
        EXPECT_EQ(vf_pairs(r.vf), vf_pairs(ref0.vf));
        EXPECT_EQ(ee_pairs(r.ee), ee_pairs(ref0.ee));
        std::vector<int> few{0, 1, 2};
        det.set_active_vertices(few);
        det.rebuild(mid);
        // The tree a build on `mid` gives, node for node, flags included.
        std::vector<Eigen::Vector3d> m(s.num_vertices), m0(s.num_vertices);
        for (int v = 0; v < s.num_vertices; ++v) {
          m[v] = mid.row(v).transpose();
          m0[v] = s.v_t0.row(v).transpose();
        }
        const Bvh fresh(topo, m, build);
        EXPECT_EQ(det.bvh().prim_ids(), fresh.prim_ids());
        ASSERT_EQ(det.bvh().nodes().size(), fresh.nodes().size());
        for (std::size_t i = 0; i < fresh.nodes().size(); ++i) {
          const BvhNode &a = det.bvh().nodes()[i], &b = fresh.nodes()[i];
          EXPECT_EQ(std::tuple(a.left, a.first, a.count, a.flags),
                    std::tuple(b.left, b.first, b.count, b.flags))
              << "node " << i;
        }
        if (Bvh(topo, m0, build).prim_ids() != fresh.prim_ids()) ++changed;
        r = det.detect(mid, s.v_t1);  // unrestricted: every pair
        EXPECT_EQ(vf_pairs(r.vf), vf_pairs(ref1.vf));
        EXPECT_EQ(ee_pairs(r.ee), ee_pairs(ref1.ee));
        det.rebuild(s.v_t1);
        const ProximityResult p = det.proximity(s.v_t1, 0.01);
        if (culling == Culling::None) {
          EXPECT_GT(p.reused_pairs, 0u);  // the kept pairs survive the rebuild
        }
        EXPECT_EQ(vf_pairs(p.vf), vf_pairs(near.vf));
        EXPECT_EQ(ee_pairs(p.ee), ee_pairs(near.ee));
      }
    }
    SelfDetector det(s.faces, s.num_vertices, s.v_t0);
    EXPECT_THROW(det.rebuild(s.v_t0.topRows(s.num_vertices - 1)), InputError);
  }
  EXPECT_GT(changed, 0);  // so the node comparison above shows a rebuild, not the old tree
}

using test::counters;

TEST(DetectApi, DeterministicOnOneTwoAndFourThreads) {
  const research::ProceduralScene s = research::crumpled_sheet(16, 5);
  const Mesh a = sheet(10);
  const Mesh b = ball(3, 0.18, {0.47, 0.52, 0.2}, {0.5, 0.49, 0.05});
  for (research::CullingRule culling :
       {research::CullingRule::None, research::CullingRule::Cone, research::CullingRule::Sound}) {
    DetectOptions o;
    o.build = BvhBuild::Patch;
    research::set_culling_rule(o, culling);
    std::optional<DetectResult> first;
    std::optional<PairDetectResult> first_pair;
    for (int threads : {1, 2, 4}) {
      SCOPED_TRACE(::testing::Message() << "culling " << int(culling) << " threads " << threads);
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      const DetectResult r = det.detect(s.v_t0, s.v_t1);
      DetectOptions po = o;
      po.culling = Culling::None;  // the two-mesh detector refuses cones
      po.research = {};
      PairDetector pd(a.faces, a.nv(), a.v0, b.faces, b.nv(), b.v0, po);
      const PairDetectResult pr = pd.detect(a.v0, a.v1, b.v0, b.v1);
      if (!first) {
        EXPECT_GT(r.vf.size() + r.ee.size(), 0u);
        EXPECT_GT(pr.vf_a_on_b.size() + pr.vf_b_on_a.size() + pr.ee.size(), 0u);
        first = r;
        first_pair = pr;
        continue;
      }
      EXPECT_EQ(r.vf, first->vf);
      EXPECT_EQ(r.ee, first->ee);
      EXPECT_EQ(counters(r.stats), counters(first->stats));
      EXPECT_EQ(pr.vf_a_on_b, first_pair->vf_a_on_b);
      EXPECT_EQ(pr.vf_b_on_a, first_pair->vf_b_on_a);
      EXPECT_EQ(pr.ee, first_pair->ee);
      EXPECT_EQ(counters(pr.stats), counters(first_pair->stats));
    }
  }
}

// Linked vertices (stitched seams) count as one point: the detector, on both builds and with and
// without culling, equals brute force with the same links, which equals brute force without links
// minus exactly the pairs that join two linked vertices.
TEST(DetectApi, LinkedVerticesDropExactlyThePairsJoiningThem) {
  const research::ProceduralScene s = research::crumpled_sheet(12, 6);
  const Topology topo(s.faces, s.num_vertices);
  const DetectResult all = research::brute_force_detect(topo, s.v_t0, s.v_t1);
  ASSERT_GE(all.vf.size(), 3u);
  ASSERT_GE(all.ee.size(), 3u);
  // Link the two ends of every third colliding VF pair (vertex with a face corner) and of every
  // third EE pair (first ends), as a seam would.
  DetectOptions o;
  for (std::size_t i = 0; i < all.vf.size(); i += 3)
    o.linked_vertices.emplace_back(all.vf[i].face_vertices[1], all.vf[i].vertex);
  for (std::size_t i = 0; i < all.ee.size(); i += 3)
    o.linked_vertices.emplace_back(all.ee[i].edge_a_vertices[0], all.ee[i].edge_b_vertices[0]);
  auto linked = [&](int u, int v) {
    for (auto [a, b] : o.linked_vertices) {
      if ((a == u && b == v) || (a == v && b == u)) return true;
    }
    return false;
  };
  DetectResult expected;
  for (const auto& c : all.vf) {
    const Face& t = c.face_vertices;
    if (!linked(c.vertex, t[0]) && !linked(c.vertex, t[1]) && !linked(c.vertex, t[2]))
      expected.vf.push_back(c);
  }
  for (const auto& c : all.ee) {
    bool any = false;
    for (int a : c.edge_a_vertices) {
      for (int b : c.edge_b_vertices)
        any = any || linked(a, b);
    }
    if (!any) expected.ee.push_back(c);
  }
  ASSERT_LT(expected.vf.size(), all.vf.size());
  ASSERT_LT(expected.ee.size(), all.ee.size());
  const DetectResult ref = research::brute_force_detect(topo, s.v_t0, s.v_t1, o);
  EXPECT_EQ(ref.vf, expected.vf);
  EXPECT_EQ(ref.ee, expected.ee);
  for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
    for (Culling culling : {Culling::None, Culling::Sound}) {
      o.build = build;
      o.culling = culling;
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      const DetectResult r = det.detect(s.v_t0, s.v_t1);
      EXPECT_EQ(r.vf, expected.vf) << int(build) << " " << int(culling);
      EXPECT_EQ(r.ee, expected.ee) << int(build) << " " << int(culling);
      // The links are kept between calls and follow set_options both ways.
      DetectOptions unlinked = o;
      unlinked.linked_vertices.clear();
      det.set_options(unlinked);
      const DetectResult u = det.detect(s.v_t0, s.v_t1);
      EXPECT_EQ(u.vf, all.vf) << int(build) << " " << int(culling);
      EXPECT_EQ(u.ee, all.ee) << int(build) << " " << int(culling);
      det.set_options(o);
      const DetectResult again = det.detect(s.v_t0, s.v_t1);
      EXPECT_EQ(again.vf, expected.vf) << int(build) << " " << int(culling);
      EXPECT_EQ(again.ee, expected.ee) << int(build) << " " << int(culling);
    }
  }
}

TEST(DetectApi, LinkedVertexOutOfRangeIsAnInputError) {
  const research::ProceduralScene s = research::crumpled_sheet(3, 1);
  DetectOptions o;
  o.linked_vertices = {{0, s.num_vertices}};
  SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
  EXPECT_THROW((void)det.detect(s.v_t0, s.v_t1), InputError);
  EXPECT_THROW((void)det.detect(s.v_t0, s.v_t1), InputError);  // still, not only once
  o.linked_vertices.clear();
  det.set_options(o);
  EXPECT_NO_THROW((void)det.detect(s.v_t0, s.v_t1));
}

}  // namespace api_test
}  // namespace clothcd
