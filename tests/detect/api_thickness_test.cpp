// The detector API with thickness > 0 against brute force (label slow: the thick CCD kernels
// take seconds on these small scenes under the sanitizers).

#include <gtest/gtest.h>

#include "api_scenes.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/oracle.hpp"
#include "clothcd/detect/procedural.hpp"

namespace clothcd {
namespace {

using namespace clothcd::test;

TEST(DetectApi, PairDetectorWithThicknessEqualsBruteForce) {
  check_pair_detector(0.003);
}

TEST(DetectApi, ThicknessEqualsBruteForce) {
  // Thick CCD kernels are slow on the near-coplanar stacked sheets, so those are left out here.
  const std::pair<ProceduralScene, double> cases[] = {
      {crumpled_sheet(7, 4), 0.001}, {crumpled_sheet(7, 4), 0.01}, {winding_strip(36, 2), 0.001}};
  for (const auto& [s, thickness] : cases) {
    const Topology topo(s.faces, s.num_vertices);
    DetectOptions o;
    o.thickness = thickness;
    const DetectResult ref = brute_force_detect(topo, s.v_t0, s.v_t1, o);
    const DetectResult thin = brute_force_detect(topo, s.v_t0, s.v_t1);
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
      }
    }
  }
}

}  // namespace
}  // namespace clothcd
