// SelfDetector::detect_each on real data (cloth_ball 92 -> 93, 92,230 triangles, both builds):
// every configuration gets what set_options() + detect() reports, collisions and counters.

#include <gtest/gtest.h>

#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/names.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"
#include "support/data.hpp"
#include "support/detect_stats.hpp"

namespace clothcd {
// A namespace of its own: the research types below stay in this file of the unity build.
namespace detect_each_data_test {

// The research detector and options (unsound rules, optimal cones, verification).
using research::DetectOptions;
using research::SelfDetector;

TEST(DetectEachData, ClothBallEqualsOneDetectPerConfiguration) {
  CLOTHCD_REQUIRE_DATA(root, "cloth-ball");
  const TriangleMesh m0 = read_mesh(root / "frames/cloth_ball92.ply");
  const TriangleMesh m1 = read_mesh(root / "frames/cloth_ball93.ply");
  const Positions p0 = vertices_matrix(m0), p1 = vertices_matrix(m1);
  std::vector<DetectOptions> configs(1);
  const std::pair<research::CullingRule, research::ConeRule> rules[] = {
      {research::CullingRule::Cone, research::ConeRule::Provot},
      {research::CullingRule::Cone, research::ConeRule::Proposed},
      {research::CullingRule::Gated, research::ConeRule::Exact},
      {research::CullingRule::Sound, research::ConeRule::Proposed},
  };
  for (const auto& [c, p] : rules) {
    DetectOptions o;
    research::set_culling_rule(o, c);
    research::set_cone_rule(o, p);
    configs.push_back(o);
  }
  for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
    SCOPED_TRACE(to_string(build));
    DetectOptions base;
    base.build = build;
    for (DetectOptions& c : configs)
      c.build = build;  // the detector's build: another one is refused
    SelfDetector det(m0.faces, m0.num_vertices(), p0, base);
    const auto each = det.detect_each(p0, p1, configs);
    ASSERT_EQ(each.size(), configs.size());
    for (std::size_t k = 0; k < configs.size(); ++k) {
      SCOPED_TRACE(testing::Message() << "configuration " << k);
      det.set_options(configs[k]);
      test::expect_same_detection(each[k], det.detect(p0, p1));
    }
    // The paper's rule misses collisions here, so the groups really differ.
    EXPECT_LT(each[1].vf.size() + each[1].ee.size(), each[0].vf.size() + each[0].ee.size());
    EXPECT_GT(each[4].stats.nodes_culled, 0u);
  }
}

}  // namespace detect_each_data_test
}  // namespace clothcd
