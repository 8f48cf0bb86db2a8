// The detector API with thickness > 0 against brute force (label slow: the thick CCD kernels
// take seconds on these small scenes under the sanitizers).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>

#include "api_scenes.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/oracle.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd {
namespace {

using namespace clothcd::test;

TEST(DetectApi, PairDetectorWithThicknessEqualsBruteForce) {
  check_pair_detector(0.003);
}

TEST(DetectApi, ThicknessEqualsBruteForce) {
  // Thick CCD kernels are slow on the near-coplanar stacked sheets, so those are left out here.
  const std::pair<research::ProceduralScene, double> cases[] = {
      {research::crumpled_sheet(7, 4), 0.001},
      {research::crumpled_sheet(7, 4), 0.01},
      {research::winding_strip(36, 2), 0.001}};
  std::uint64_t apart = 0, culled = 0;
  for (const auto& [s, thickness] : cases) {
    const Topology topo(s.faces, s.num_vertices);
    DetectOptions o;
    o.thickness = thickness;
    const DetectResult ref = research::brute_force_detect(topo, s.v_t0, s.v_t1, o);
    const DetectResult thin = research::brute_force_detect(topo, s.v_t0, s.v_t1);
    // A thickness finds at least what zero thickness finds.
    EXPECT_GT(thin.vf.size() + thin.ee.size(), 0u) << s.name;
    EXPECT_GE(ref.vf.size() + ref.ee.size(), thin.vf.size() + thin.ee.size()) << s.name;
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      for (Culling culling : {Culling::None, Culling::Sound}) {
        SCOPED_TRACE(::testing::Message() << s.name << " thickness " << thickness << " build "
                                          << int(build) << " culling " << int(culling));
        o.build = build;
        o.culling = culling;
        SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
        const DetectResult r = det.detect(s.v_t0, s.v_t1);
        EXPECT_EQ(r.vf, ref.vf);
        EXPECT_EQ(r.ee, ref.ee);
        apart += r.stats.triangle_pairs_apart;
        culled += r.stats.nodes_culled;
      }
    }
  }
  // The detector culled whole triangle pairs that the oracle tests feature by feature, with the
  // same result.
  EXPECT_GT(apart, 0u);
  // Sound culling with a thickness (docs/algorithms.md 1.6) skipped some nodes, losing nothing.
  EXPECT_GT(culled, 0u);
}

// Smallest distance of a feature pair along the step, sampled at 2001 instants.
template <class Distance>
double sampled_min(Distance&& at) {
  double d = INFINITY;
  for (int i = 0; i <= 2000; ++i)
    d = std::min(d, at(i / 2000.0));
  return d;
}

TEST(DetectApi, DeeperDistanceFilterDropsOnlyPairsThatStayApart) {
  // The thick kernels are conservative (a hit certifies a distance within sqrt(3) thickness):
  // the deeper filter drops some of those hits, and only ones whose pair stays apart.
  const std::pair<research::ProceduralScene, double> cases[] = {
      {research::crumpled_sheet(7, 4), 0.001},
      {research::crumpled_sheet(7, 4), 0.01},
      {research::winding_strip(36, 2), 0.001}};
  std::size_t dropped = 0;
  for (const auto& entry : cases) {
    // Named, not structured bindings: the lambdas below capture them (clang 14 cannot).
    const research::ProceduralScene& s = entry.first;
    const double thickness = entry.second;
    SCOPED_TRACE(::testing::Message() << s.name << " thickness " << thickness);
    const Topology topo(s.faces, s.num_vertices);
    DetectOptions o;
    o.thickness = thickness;
    const DetectResult ref = research::brute_force_detect(topo, s.v_t0, s.v_t1, o);
    o.distance_filter_depth = 6;
    const DetectResult deep = research::brute_force_detect(topo, s.v_t0, s.v_t1, o);
    EXPECT_GT(deep.vf.size() + deep.ee.size(), 0u);
    auto at = [&](int i, double t) {
      return Eigen::Vector3d(s.v_t0.row(i) + t * (s.v_t1.row(i) - s.v_t0.row(i)));
    };
    std::vector<VertexFaceCollision> dropped_vf;
    std::set_difference(ref.vf.begin(), ref.vf.end(), deep.vf.begin(), deep.vf.end(),
                        std::back_inserter(dropped_vf), [](const auto& a, const auto& b) {
                          return std::pair(a.vertex, a.face) < std::pair(b.vertex, b.face);
                        });
    for (const auto& c : dropped_vf) {
      const Face& f = c.face_vertices;
      const double d = sampled_min([&](double t) {
        return point_triangle_proximity(at(c.vertex, t), at(f[0], t), at(f[1], t), at(f[2], t))
            .distance;
      });
      EXPECT_GT(d, thickness) << "vertex " << c.vertex << " face " << c.face;
    }
    std::vector<EdgeEdgeCollision> dropped_ee;
    std::set_difference(ref.ee.begin(), ref.ee.end(), deep.ee.begin(), deep.ee.end(),
                        std::back_inserter(dropped_ee), [](const auto& a, const auto& b) {
                          return std::pair(a.edge_a, a.edge_b) < std::pair(b.edge_a, b.edge_b);
                        });
    for (const auto& c : dropped_ee) {
      const Edge &a = c.edge_a_vertices, &b = c.edge_b_vertices;
      const double d = sampled_min([&](double t) {
        return edge_edge_proximity(at(a[0], t), at(a[1], t), at(b[0], t), at(b[1], t)).distance;
      });
      EXPECT_GT(d, thickness) << "edges " << c.edge_a << " " << c.edge_b;
    }
    // Nothing new appears (deep is a subset of ref), and the detector agrees with the oracle at
    // the same depth.
    EXPECT_EQ(deep.vf.size() + dropped_vf.size(), ref.vf.size());
    EXPECT_EQ(deep.ee.size() + dropped_ee.size(), ref.ee.size());
    dropped += dropped_vf.size() + dropped_ee.size();
    for (Culling culling : {Culling::None, Culling::Sound}) {
      o.culling = culling;
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      const DetectResult r = det.detect(s.v_t0, s.v_t1);
      EXPECT_EQ(r.vf, deep.vf);
      EXPECT_EQ(r.ee, deep.ee);
    }
  }
  EXPECT_GT(dropped, 0u);  // 3 on the crumpled sheet at 1 cm, so the checks above bite
}

}  // namespace
}  // namespace clothcd
