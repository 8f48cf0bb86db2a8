// SelfDetector::detect_each against its definition: for every configuration, the collisions and
// counters of set_options() + detect() on the same step, whatever the mix of rules, policies,
// builds, thicknesses and thread counts; and its refusals.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/names.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"
#include "clothcd/research/procedural.hpp"
#include "support/detect_stats.hpp"

namespace clothcd {
// A namespace of its own: the research types below stay in this file of the unity build.
namespace detect_each_test {

// The research detector and options (unsound rules, optimal cones, verification).
using research::DetectOptions;
using research::SelfDetector;

using research::ConeRule;
using research::CullingRule;

// Every rule with every cone rule, the reference first (as the experiment asks), then the sound
// rule with a node-size threshold.
std::vector<DetectOptions> all_configs(double thickness) {
  std::vector<DetectOptions> out;
  DetectOptions none;
  none.thickness = thickness;
  out.push_back(none);
  for (CullingRule c : {CullingRule::Cone, CullingRule::Gated, CullingRule::Sound}) {
    for (ConeRule p : {ConeRule::Provot, ConeRule::Proposed, ConeRule::Exact, ConeRule::Optimal}) {
      DetectOptions o = none;
      research::set_culling_rule(o, c);
      research::set_cone_rule(o, p);
      out.push_back(o);
    }
  }
  DetectOptions sized = none;
  sized.culling = Culling::Sound;
  sized.cull_min_triangles = 16;
  out.push_back(sized);
  return out;
}

// Each scene with the thicknesses it is run at: a thickness makes the kernels' work grow fast
// on these tight folds, so the larger scenes run at zero thickness only.
struct Case {
  research::ProceduralScene scene;
  std::vector<double> thicknesses;
};
std::vector<Case> cases() {
  return {{research::stacked_sheets(8), {0.0}},
          {research::winding_strip(96, 3), {0.0}},
          {research::crumpled_sheet(14, 3), {0.0}},
          {research::crumpled_sheet(8, 5), {2e-3}},
          {research::twisted_strip(60, 4), {0.0}}};
}

TEST(DetectEach, EqualsOneDetectPerConfiguration) {
  for (const auto& [s, thicknesses] : cases()) {
    std::uint64_t culled = 0;  // by any configuration, on either build
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      for (double thickness : thicknesses) {
        for (int threads : {1, 2}) {
          const tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                          static_cast<std::size_t>(threads));
          SCOPED_TRACE(testing::Message() << s.name << " " << to_string(build) << " thickness "
                                          << thickness << " threads " << threads);
          DetectOptions base;
          base.build = build;
          SelfDetector det(s.faces, s.num_vertices, s.v_t0, base);
          auto configs = all_configs(thickness);
          for (DetectOptions& c : configs)
            c.build = build;  // the detector's build: another one is refused
          const auto each = det.detect_each(s.v_t0, s.v_t1, configs);
          ASSERT_EQ(each.size(), configs.size());
          // The detector's own options are back.
          EXPECT_TRUE(det.options() == base);
          for (std::size_t k = 0; k < configs.size(); ++k) {
            SCOPED_TRACE(testing::Message() << "configuration " << k);
            DetectOptions o = configs[k];
            o.build = build;
            SelfDetector one(s.faces, s.num_vertices, s.v_t0, o);
            const DetectResult r = one.detect(s.v_t0, s.v_t1);
            test::expect_same_detection(each[k], r);
            EXPECT_TRUE(std::isnan(each[k].stats.time_traverse));
            EXPECT_TRUE(std::isnan(each[k].stats.time_narrow));
            culled += each[k].stats.nodes_culled;
          }
          EXPECT_GT(each[0].vf.size() + each[0].ee.size(), 0u);  // the step collides
        }
      }
    }
    // ... and the rules cull: the configurations really split the pairs into groups.
    EXPECT_GT(culled, 0u) << s.name;
  }
}

// The same detector, called for both forms, after a detect() and before one: state from one
// call (moved-vertex refits, cones of another policy) must not leak into the next.
TEST(DetectEach, InterleavesWithDetect) {
  const research::ProceduralScene s = research::crumpled_sheet(16, 11);
  DetectOptions sound;
  sound.culling = Culling::Sound;
  SelfDetector det(s.faces, s.num_vertices, s.v_t0, sound);
  SelfDetector ref(s.faces, s.num_vertices, s.v_t0, sound);
  const Positions mid = 0.5 * (s.v_t0 + s.v_t1);
  const auto configs = all_configs(0.0);
  for (int round = 0; round < 2; ++round) {
    const DetectResult a = det.detect(s.v_t0, mid);
    test::expect_same_detection(a, ref.detect(s.v_t0, mid));
    std::vector<Eigen::Vector3d> p0(static_cast<std::size_t>(s.v_t0.rows())), p1(p0.size());
    for (Eigen::Index i = 0; i < s.v_t0.rows(); ++i) {
      p0[static_cast<std::size_t>(i)] = mid.row(i).transpose();
      p1[static_cast<std::size_t>(i)] = s.v_t1.row(i).transpose();
    }
    const auto each = det.detect_each(p0, p1, configs);
    for (std::size_t k = 0; k < configs.size(); ++k) {
      SelfDetector one(s.faces, s.num_vertices, s.v_t0, configs[k]);
      test::expect_same_detection(each[k], one.detect(mid, s.v_t1));
    }
    test::expect_same_detection(det.detect(mid, s.v_t1), ref.detect(mid, s.v_t1));
  }
}

TEST(DetectEach, RefusesConfigurationsThatShareNoNarrowPhase) {
  const research::ProceduralScene s = research::stacked_sheets(6);
  SelfDetector det(s.faces, s.num_vertices, s.v_t0);
  const DetectOptions before = det.options();
  auto refused = [&](std::vector<DetectOptions> configs) {
    EXPECT_THROW((void)det.detect_each(s.v_t0, s.v_t1, configs), InputError);
    EXPECT_TRUE(det.options() == before);
  };
  DetectOptions a, b;
  b.thickness = 1e-3;  // other boxes
  refused({a, b});
  b = a;
  b.np_filter = false;  // other kernels
  refused({a, b});
  b = a;
  b.linked_vertices = {{0, 1}};
  refused({a, b});
  b = a;
  b.reuse_distance = 1e-3;
  refused({b});
  b = a;
  b.research.verify = true;
  refused({b});
  b = a;
  b.thickness = -1;
  refused({b});
  b = a;
  b.build = BvhBuild::Patch;  // the detector's tree is the spatial build
  refused({b});
  refused(std::vector<DetectOptions>(65, a));
  const std::vector<int> active{0, 1};
  det.set_active_faces(active);
  refused({a});
  det.clear_active();
  EXPECT_TRUE(det.detect_each(s.v_t0, s.v_t1, std::vector<DetectOptions>{}).empty());
  // Positions of the wrong size are refused too, with the positions named.
  const Positions short_one = s.v_t0.topRows(3);
  EXPECT_THROW((void)det.detect_each(short_one, s.v_t1, std::vector<DetectOptions>{a}), InputError);
}

}  // namespace detect_each_test
}  // namespace clothcd
