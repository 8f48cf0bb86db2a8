// The detector against the brute-force oracle on procedural scenes: exact collision sets for the
// sound modes in every cone policy and both BVH builds; the unsound research rules miss where
// expected, and the research verification reports exactly those misses.

#include <gtest/gtest.h>

#include <tuple>

#include "clothcd/detect/detector.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"
#include "clothcd/research/oracle.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd {
// A namespace of its own: the research types below stay in this file of the unity build.
namespace oracle_test {

// The research detector and options (unsound rules, optimal cones, verification).
using research::DetectOptions;
using research::SelfDetector;

std::vector<std::pair<int, int>> vf_set(const std::vector<VertexFaceCollision>& c) {
  std::vector<std::pair<int, int>> s;
  for (const auto& x : c)
    s.emplace_back(x.vertex, x.face);
  return s;
}
std::vector<std::pair<int, int>> ee_set(const std::vector<EdgeEdgeCollision>& c) {
  std::vector<std::pair<int, int>> s;
  for (const auto& x : c)
    s.emplace_back(x.edge_a, x.edge_b);
  return s;
}

std::vector<research::ProceduralScene> scenes() {
  std::vector<research::ProceduralScene> s{
      research::stacked_sheets(10), research::winding_strip(72, 3), research::twisted_strip(60, 4)};
  for (std::uint64_t seed = 1; seed <= 3; ++seed)
    s.push_back(research::crumpled_sheet(14, seed));
  return s;
}

constexpr research::ConeRule kPolicies[] = {research::ConeRule::Provot,
                                            research::ConeRule::Proposed, research::ConeRule::Exact,
                                            research::ConeRule::Optimal};
constexpr BvhBuild kBuilds[] = {BvhBuild::Spatial, BvhBuild::Patch};

research::DetectResult run(const research::ProceduralScene& s, DetectOptions o) {
  SelfDetector d(s.faces, s.num_vertices, s.v_t0, o);
  return d.detect(s.v_t0, s.v_t1);
}

TEST(DetectOracle, NoneAndSoundEqualBruteForce) {
  for (const auto& s : scenes()) {
    const Topology topo(s.faces, s.num_vertices);
    const DetectResult ref = research::brute_force_detect(topo, s.v_t0, s.v_t1);
    EXPECT_GT(ref.vf.size() + ref.ee.size(), 0u) << s.name << ": the motion must collide";
    for (BvhBuild build : kBuilds) {
      for (research::ConeRule policy : kPolicies) {
        for (Culling culling : {Culling::None, Culling::Sound}) {
          DetectOptions o;
          o.build = build;
          research::set_cone_rule(o, policy);
          o.culling = culling;
          const research::DetectResult r = run(s, o);
          SCOPED_TRACE(::testing::Message() << s.name << " build " << int(build) << " policy "
                                            << int(policy) << " culling " << int(culling));
          EXPECT_EQ(vf_set(r.vf), vf_set(ref.vf));
          EXPECT_EQ(ee_set(r.ee), ee_set(ref.ee));
          ASSERT_EQ(r.vf.size(), ref.vf.size());
          for (std::size_t i = 0; i < r.vf.size(); ++i)
            EXPECT_EQ(r.vf[i].toi, ref.vf[i].toi);
        }
      }
    }
  }
}

// Misses of the unsound modes, measured with the verify option (which runs the unculled
// traversal too and must agree with a direct comparison).
struct Misses {
  std::size_t missed = 0;
  std::size_t found_by_none = 0;
};

Misses misses(const research::ProceduralScene& s, research::CullingRule culling,
              research::ConeRule policy, BvhBuild build) {
  DetectOptions o;
  research::set_culling_rule(o, culling);
  research::set_cone_rule(o, policy);
  o.build = build;
  o.research.verify = true;
  const research::DetectResult r = run(s, o);
  const research::Verification& v = r.verification;
  EXPECT_TRUE(v.ran);
  o.culling = Culling::None;
  o.research = {};
  const DetectResult all = run(s, o);
  EXPECT_EQ(v.missed_vf.size() + r.vf.size(), all.vf.size());
  EXPECT_EQ(v.missed_ee.size() + r.ee.size(), all.ee.size());
  return {v.missed_vf.size() + v.missed_ee.size(), all.vf.size() + all.ee.size()};
}

// The research options directly, as a measurement sets them: an unsound rule overrides the
// culling, and verify lists what it missed.
TEST(DetectOracle, ResearchOptionsOverrideTheCullingAndVerifyListsTheMisses) {
  const auto s = research::winding_strip(72, 3);
  DetectOptions o;
  o.build = BvhBuild::Patch;
  o.culling = Culling::Sound;
  o.research.culling = research::CullingRule::Gated;
  o.research.verify = true;
  EXPECT_EQ(research::culling_rule(o), research::CullingRule::Gated);
  const research::DetectResult gated = run(s, o);
  ASSERT_TRUE(gated.verification.ran);
  EXPECT_GT(gated.verification.missed_vf.size() + gated.verification.missed_ee.size(), 0u);
  EXPECT_GT(gated.verification.unculled_triangle_pairs, gated.stats.triangle_pairs);
  o.research.culling.reset();
  const research::DetectResult sound = run(s, o);
  ASSERT_TRUE(sound.verification.ran);
  EXPECT_TRUE(sound.verification.missed_vf.empty());
  EXPECT_TRUE(sound.verification.missed_ee.empty());
  o.culling = Culling::None;
  EXPECT_FALSE(run(s, o).verification.ran);  // nothing culled, nothing to verify
}

TEST(DetectOracle, ConeMissesStackedSheetsGatedDoesNot) {
  const auto s = research::stacked_sheets(10);
  for (BvhBuild build : kBuilds) {
    for (research::ConeRule policy : kPolicies) {
      const Misses cone = misses(s, research::CullingRule::Cone, policy, build);
      EXPECT_GT(cone.found_by_none, 0u);
      EXPECT_GT(cone.missed, 0u) << "policy " << int(policy) << " build " << int(build);
      EXPECT_EQ(misses(s, research::CullingRule::Gated, policy, build).missed, 0u);
      EXPECT_EQ(misses(s, research::CullingRule::Sound, policy, build).missed, 0u);
    }
  }
}

TEST(DetectOracle, GatedMissesWindingStripSoundDoesNot) {
  const auto s = research::winding_strip(72, 3);
  for (BvhBuild build : kBuilds) {
    for (research::ConeRule policy : kPolicies) {
      SCOPED_TRACE(::testing::Message() << "policy " << int(policy) << " build " << int(build));
      EXPECT_GT(misses(s, research::CullingRule::Cone, policy, build).missed, 0u);
      EXPECT_GT(misses(s, research::CullingRule::Gated, policy, build).missed, 0u);
      EXPECT_EQ(misses(s, research::CullingRule::Sound, policy, build).missed, 0u);
    }
  }
}

}  // namespace oracle_test
}  // namespace clothcd
