// The two-mesh detector with a simulator's settings against brute force on exact pair sets:
// thickness > 0 with the distance filter and its bisections, a coarse toi tolerance, active
// vertices, repeated calls with a few moved vertices, proximity with distances; and the options
// it refuses.

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "api_scenes.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/oracle.hpp"

namespace clothcd {
namespace {

using namespace clothcd::test;

// The ball rests on the sheet (a body under a garment): a thick step finds resting contact.
struct Scene {
  Mesh a = sheet(6);
  Mesh b = ball(2, 0.18, {0.47, 0.52, 0.17}, {0.48, 0.5, 0.15});
  Topology ta{a.faces, a.nv()}, tb{b.faces, b.nv()};
};

DetectOptions simulator_options(double thickness, int depth) {
  DetectOptions o;
  o.thickness = thickness;
  o.distance_filter_depth = depth;
  o.toi_tolerance = 0.05;
  return o;
}

// The brute-force pairs that the active restriction keeps (a vertex of A flagged in `act`).
PairDetectResult restricted(PairDetectResult r, const Topology& ta, const Topology& tb,
                            const std::vector<std::uint8_t>& act) {
  auto face_active = [&](const Face& f) { return act[f[0]] || act[f[1]] || act[f[2]]; };
  std::erase_if(r.vf_a_on_b, [&](const VertexFaceCollision& c) { return !act[c.vertex]; });
  std::erase_if(r.vf_b_on_a,
                [&](const VertexFaceCollision& c) { return !face_active(ta.faces()[c.face]); });
  std::erase_if(r.ee, [&](const EdgeEdgeCollision& c) {
    return !act[c.edge_a_vertices[0]] && !act[c.edge_a_vertices[1]];
  });
  (void)tb;
  return r;
}

TEST(PairDetector, ThickStepsEqualBruteForceWithFilterDepthAndToiTolerance) {
  const Scene s;
  for (int depth : {0, 4}) {
    const DetectOptions o = simulator_options(0.004, depth);
    const PairDetectResult ref =
        research::brute_force_detect_pair(s.ta, s.a.v0, s.a.v1, s.tb, s.b.v0, s.b.v1, o);
    EXPECT_GT(ref.vf_a_on_b.size(), 0u);
    EXPECT_GT(ref.vf_b_on_a.size(), 0u);
    EXPECT_GT(ref.ee.size(), 0u);
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      SCOPED_TRACE(::testing::Message() << "depth " << depth << " build " << int(build));
      DetectOptions ob = o;
      ob.build = build;
      PairDetector det(s.a.faces, s.a.nv(), s.a.v0, s.b.faces, s.b.nv(), s.b.v0, ob);
      const PairDetectResult r = det.detect(s.a.v0, s.a.v1, s.b.v0, s.b.v1);
      expect_pair_equal(r, ref);
      EXPECT_GT(r.stats.vf_np_culled + r.stats.ee_np_culled, 0u);  // the distance filter ran
    }
  }
}

// Every filter setting, at zero thickness and with one: the batched stages (NP filter, distance
// filter, fast path) where the settings have them, the scalar path one query at a time where they
// have none; brute force runs the scalar path on every pair.
TEST(PairDetector, EveryFilterSettingEqualsBruteForce) {
  const Scene s;
  for (double thickness : {0.0, 0.004}) {
    for (int bits = 0; bits < 8; ++bits) {
      DetectOptions o = simulator_options(thickness, 4);
      o.np_filter = (bits & 1) != 0;
      o.fast_path = (bits & 2) != 0;
      o.distance_filter = (bits & 4) != 0;
      SCOPED_TRACE(::testing::Message()
                   << "thickness " << thickness << " np " << o.np_filter << " fast " << o.fast_path
                   << " distance " << o.distance_filter);
      const PairDetectResult ref =
          research::brute_force_detect_pair(s.ta, s.a.v0, s.a.v1, s.tb, s.b.v0, s.b.v1, o);
      EXPECT_GT(ref.vf_a_on_b.size() + ref.vf_b_on_a.size() + ref.ee.size(), 0u);
      PairDetector det(s.a.faces, s.a.nv(), s.a.v0, s.b.faces, s.b.nv(), s.b.v0, o);
      expect_pair_equal(det.detect(s.a.v0, s.a.v1, s.b.v0, s.b.v1), ref);
    }
  }
}

TEST(PairDetector, ActiveVerticesKeepExactlyThePairsWithAnActiveVertex) {
  const Scene s;
  const DetectOptions o = simulator_options(0.004, 6);
  const PairDetectResult all =
      research::brute_force_detect_pair(s.ta, s.a.v0, s.a.v1, s.tb, s.b.v0, s.b.v1, o);
  PairDetector det(s.a.faces, s.a.nv(), s.a.v0, s.b.faces, s.b.nv(), s.b.v0, o);
  std::vector<int> active;
  std::vector<std::uint8_t> act(s.a.nv(), 0);
  for (int v = 0; v < s.a.nv(); v += 3) {
    active.push_back(v);
    act[v] = 1;
  }
  det.set_active_vertices(active);
  const PairDetectResult ref = restricted(all, s.ta, s.tb, act);
  const PairDetectResult r = det.detect(s.a.v0, s.a.v1, s.b.v0, s.b.v1);
  const std::size_t n_ref = ref.vf_a_on_b.size() + ref.vf_b_on_a.size() + ref.ee.size();
  EXPECT_GT(n_ref, 0u);
  EXPECT_LT(n_ref, all.vf_a_on_b.size() + all.vf_b_on_a.size() + all.ee.size());
  expect_pair_equal(r, ref);
  // Active vertices of B alone: pairs touching them, none of A's.
  det.set_active_vertices({}, std::vector<int>{0, 1, 2, 3});
  const PairDetectResult rb = det.detect(s.a.v0, s.a.v1, s.b.v0, s.b.v1);
  for (const auto& c : rb.vf_b_on_a)
    EXPECT_LT(c.vertex, 4);
  det.clear_active();
  expect_pair_equal(det.detect(s.a.v0, s.a.v1, s.b.v0, s.b.v1), all);
}

TEST(PairDetector, RepeatedCallsWithFewMovedVerticesEqualBruteForce) {
  const Scene s;
  const DetectOptions o = simulator_options(0.004, 6);
  PairDetector det(s.a.faces, s.a.nv(), s.a.v0, s.b.faces, s.b.nv(), s.b.v0, o);
  (void)det.detect(s.a.v0, s.a.v1, s.b.v0, s.b.v1);
  Positions a1 = s.a.v1;
  for (int round = 0; round < 3; ++round) {
    for (int v = round; v < s.a.nv(); v += 7)
      a1(v, 2) += 0.01 * (round % 2 == 0 ? 1 : -1);  // a pass's changed velocities
    SCOPED_TRACE(::testing::Message() << "round " << round);
    const PairDetectResult ref =
        research::brute_force_detect_pair(s.ta, s.a.v0, a1, s.tb, s.b.v0, s.b.v1, o);
    expect_pair_equal(det.detect(s.a.v0, a1, s.b.v0, s.b.v1), ref);
  }
  det.rebuild(a1, s.b.v1);  // trees split on another shape: the same pairs
  expect_pair_equal(det.detect(s.a.v0, a1, s.b.v0, s.b.v1),
                    research::brute_force_detect_pair(s.ta, s.a.v0, a1, s.tb, s.b.v0, s.b.v1, o));
}

// Every pair within h by direct distances.
PairProximityResult brute_force_pair_proximity(const Topology& ta, const Positions& pa,
                                               const Topology& tb, const Positions& pb, double h) {
  auto pt = [](const Positions& p, int v) { return Eigen::Vector3d(p.row(v).transpose()); };
  PairProximityResult r;
  auto vf = [&](const Topology& tv, const Positions& pv, const Topology& tf, const Positions& pf,
                std::vector<ProximityResult::VertexFace>& out) {
    for (int v = 0; v < tv.num_vertices(); ++v) {
      if (tv.vertex_faces(v).empty()) continue;
      for (int f = 0; f < tf.num_faces(); ++f) {
        const Face& x = tf.faces()[f];
        const double d =
            point_triangle_proximity(pt(pv, v), pt(pf, x[0]), pt(pf, x[1]), pt(pf, x[2])).distance;
        if (d <= h) out.push_back({v, f, d});
      }
    }
  };
  vf(ta, pa, tb, pb, r.vf_a_on_b);
  vf(tb, pb, ta, pa, r.vf_b_on_a);
  for (int a = 0; a < ta.num_edges(); ++a) {
    for (int b = 0; b < tb.num_edges(); ++b) {
      const Edge &x = ta.edges()[a], &y = tb.edges()[b];
      const double d =
          edge_edge_proximity(pt(pa, x[0]), pt(pa, x[1]), pt(pb, y[0]), pt(pb, y[1])).distance;
      if (d <= h) r.ee.push_back({a, b, d});
    }
  }
  return r;
}

template <class A, class B>
void expect_same_items(const A& r, const B& ref) {
  ASSERT_EQ(r.size(), ref.size());
  for (std::size_t i = 0; i < r.size(); ++i) {
    if constexpr (requires { r[i].vertex; }) {
      EXPECT_EQ(std::pair(r[i].vertex, r[i].face), std::pair(ref[i].vertex, ref[i].face));
    } else {
      EXPECT_EQ(std::pair(r[i].edge_a, r[i].edge_b), std::pair(ref[i].edge_a, ref[i].edge_b));
    }
    EXPECT_EQ(r[i].distance, ref[i].distance);
  }
}

TEST(PairDetector, ProximityEqualsAllPairsDistance) {
  const Scene s;
  const Positions a = 0.5 * (s.a.v0 + s.a.v1), b = s.b.v1;
  for (double h : {0.0, 0.004, 0.03}) {
    const PairProximityResult ref = brute_force_pair_proximity(s.ta, a, s.tb, b, h);
    if (h > 0.01) {
      EXPECT_GT(ref.vf_a_on_b.size(), 0u);
      EXPECT_GT(ref.vf_b_on_a.size(), 0u);
      EXPECT_GT(ref.ee.size(), 0u);
    }
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      SCOPED_TRACE(::testing::Message() << "h " << h << " build " << int(build));
      DetectOptions o;
      o.build = build;
      PairDetector det(s.a.faces, s.a.nv(), s.a.v0, s.b.faces, s.b.nv(), s.b.v0, o);
      // After a CCD call, as in a simulator's substep.
      (void)det.detect(s.a.v0, s.a.v1, s.b.v0, s.b.v1);
      const PairProximityResult r = det.proximity(a, b, h);
      expect_same_items(r.vf_a_on_b, ref.vf_a_on_b);
      expect_same_items(r.vf_b_on_a, ref.vf_b_on_a);
      expect_same_items(r.ee, ref.ee);
    }
  }
}

TEST(PairDetector, RefusesOptionsItCannotHonour) {
  const Scene s;
  auto make = [&](const DetectOptions& o) {
    PairDetector det(s.a.faces, s.a.nv(), s.a.v0, s.b.faces, s.b.nv(), s.b.v0, o);
  };
  DetectOptions o;
  o.culling = Culling::Sound;
  EXPECT_THROW(make(o), InputError);
  o = {};
  o.reuse_distance = 0.001;
  EXPECT_THROW(make(o), InputError);
  o = {};
  o.linked_vertices = {{0, 1}};
  EXPECT_THROW(make(o), InputError);
  o = {};
  o.thickness = -1;
  EXPECT_THROW(make(o), InputError);
  PairDetector det(s.a.faces, s.a.nv(), s.a.v0, s.b.faces, s.b.nv(), s.b.v0);
  o = {};
  o.culling = Culling::Sound;
  EXPECT_THROW(det.set_options(o), InputError);
  o = {};
  o.build = BvhBuild::Patch;  // built spatial: the build is fixed at construction
  EXPECT_THROW(det.set_options(o), InputError);
  EXPECT_EQ(det.options().build, BvhBuild::Spatial);
  EXPECT_THROW(det.set_active_vertices(std::vector<int>{s.a.nv()}), InputError);
  EXPECT_THROW((void)det.proximity(s.a.v0, s.b.v0, -1.0), InputError);
}

}  // namespace
}  // namespace clothcd
