// The filter pipeline, one table over every combination of thickness, NP filter, distance filter
// and fast path: the plan each resolves to, and for each, both detectors' CCD (the batched
// pipeline of the pair loop) against brute force (every feature pair through the plan's filters
// one query at a time), exact pair sets and times, on a self scene and a two-mesh scene; and the
// proximity queries, which no filter setting may change, against the same query brute force.

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "api_scenes.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/oracle.hpp"
#include "clothcd/research/procedural.hpp"
#include "detect/feature_context.hpp"

namespace clothcd {
namespace {

using detail::FeatureFilter;
using namespace clothcd::test;

struct Row {
  double thickness;
  bool np, distance, fast;
  // The plan expected
  bool faces_apart;
  FeatureFilter single, batch;
  bool settle;
};

constexpr double kH = 0.004;
constexpr FeatureFilter kNone = FeatureFilter::None, kNp = FeatureFilter::Np,
                        kNpDist = FeatureFilter::NpDistance, kDist = FeatureFilter::Distance;

// thickness, np_filter, distance_filter, fast_path -> faces_apart, single, batch, settle
constexpr Row kRows[] = {
    {0, false, false, false, false, kNone, kNone, false},
    {0, false, false, true, false, kNone, kNp, true},  // the fast path's own NP, batched
    {0, false, true, false, false, kNone, kNone, false},
    {0, false, true, true, false, kNone, kNp, true},
    {0, true, false, false, false, kNp, kNp, false},
    {0, true, false, true, false, kNone, kNp, true},  // the kernel runs the NP filter itself
    {0, true, true, false, true, kNpDist, kNpDist, false},
    {0, true, true, true, true, kNpDist, kNpDist, true},
    {kH, false, false, false, false, kNone, kNone, false},
    {kH, false, false, true, false, kNone, kNone, false},
    {kH, false, true, false, false, kNone, kNone, false},
    {kH, false, true, true, false, kNone, kNone, false},
    {kH, true, false, false, true, kDist, kDist, false},
    {kH, true, false, true, true, kDist, kDist, false},
    {kH, true, true, false, true, kDist, kDist, false},
    {kH, true, true, true, true, kDist, kDist, false},
};

DetectOptions options_of(const Row& r) {
  DetectOptions o;
  o.thickness = r.thickness;
  o.np_filter = r.np;
  o.distance_filter = r.distance;
  o.fast_path = r.fast;
  o.distance_filter_depth = 4;
  return o;
}

std::string describe(const Row& r) {
  return ::testing::PrintToString(r.thickness) + (r.np ? " np" : " no-np") +
         (r.distance ? " distance" : " no-distance") + (r.fast ? " fast" : " no-fast");
}

template <class T>
void expect_same(const std::vector<T>& a, const std::vector<T>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    if constexpr (requires { a[i].vertex; }) {
      EXPECT_EQ(a[i].vertex, b[i].vertex);
      EXPECT_EQ(a[i].face, b[i].face);
    } else {
      EXPECT_EQ(a[i].edge_a, b[i].edge_a);
      EXPECT_EQ(a[i].edge_b, b[i].edge_b);
    }
    EXPECT_EQ(a[i].toi, b[i].toi);
  }
}

TEST(FilterPlan, EveryCombinationResolvesToItsRow) {
  for (const Row& r : kRows) {
    SCOPED_TRACE(describe(r));
    const DetectOptions o = options_of(r);
    const detail::FilterPlan p = detail::filter_plan(o.thickness, o.np_filter, o.distance_filter,
                                                     o.fast_path, o.distance_filter_depth);
    EXPECT_EQ(p.faces_apart, r.faces_apart);
    EXPECT_EQ(p.single, r.single);
    EXPECT_EQ(p.batch, r.batch);
    EXPECT_EQ(p.settle, r.settle);
    EXPECT_EQ(p.count_np, r.np);
    EXPECT_TRUE(p.kernel);
    EXPECT_EQ(p.distance_depth, 4);
  }
}

TEST(FilterPlan, EveryCombinationEqualsBruteForceInBothDetectors) {
  const research::ProceduralScene self = research::crumpled_sheet(10, 5);
  const Topology self_topo(self.faces, self.num_vertices);
  const Mesh a = sheet(6);
  const Mesh b = ball(2, 0.18, {0.47, 0.52, 0.17}, {0.48, 0.5, 0.15});
  const Topology ta(a.faces, a.nv()), tb(b.faces, b.nv());
  for (const Row& r : kRows) {
    SCOPED_TRACE(describe(r));
    const DetectOptions o = options_of(r);
    const DetectResult ref = research::brute_force_detect(self_topo, self.v_t0, self.v_t1, o);
    EXPECT_GT(ref.vf.size() + ref.ee.size(), 0u);
    SelfDetector sd(self.faces, self.num_vertices, self.v_t0, o);
    const DetectResult got = sd.detect(self.v_t0, self.v_t1);
    expect_same(got.vf, ref.vf);
    expect_same(got.ee, ref.ee);
    // The batched filters cull what the filters of one query at a time cull; the whole-triangle
    // bound spares them some.
    if (r.faces_apart) {
      EXPECT_GT(got.stats.triangle_pairs_apart, 0u);
      EXPECT_LE(got.stats.vf_np_culled + got.stats.ee_np_culled,
                ref.stats.vf_np_culled + ref.stats.ee_np_culled);
    } else {
      EXPECT_EQ(got.stats.triangle_pairs_apart, 0u);
      EXPECT_EQ(got.stats.vf_np_culled, ref.stats.vf_np_culled);
      EXPECT_EQ(got.stats.ee_np_culled, ref.stats.ee_np_culled);
    }

    const PairDetectResult pref =
        research::brute_force_detect_pair(ta, a.v0, a.v1, tb, b.v0, b.v1, o);
    EXPECT_GT(pref.vf_a_on_b.size() + pref.vf_b_on_a.size() + pref.ee.size(), 0u);
    PairDetector pd(a.faces, a.nv(), a.v0, b.faces, b.nv(), b.v0, o);
    const PairDetectResult pgot = pd.detect(a.v0, a.v1, b.v0, b.v1);
    expect_same(pgot.vf_a_on_b, pref.vf_a_on_b);
    expect_same(pgot.vf_b_on_a, pref.vf_b_on_a);
    expect_same(pgot.ee, pref.ee);
  }
}

// The proximity queries run no CCD filter: every setting gives the distance oracle's pairs.
TEST(FilterPlan, ProximityIgnoresTheFilterSettings) {
  const research::ProceduralScene self = research::crumpled_sheet(10, 5);
  const Topology self_topo(self.faces, self.num_vertices);
  const double h = 0.02;
  const ProximityResult ref = brute_force_proximity(self_topo, self.v_t1, h);
  ASSERT_GT(ref.vf.size() + ref.ee.size(), 0u);
  for (const Row& r : kRows) {
    SCOPED_TRACE(describe(r));
    SelfDetector sd(self.faces, self.num_vertices, self.v_t0, options_of(r));
    const ProximityResult got = sd.proximity(self.v_t1, h);
    ASSERT_EQ(got.vf.size(), ref.vf.size());
    ASSERT_EQ(got.ee.size(), ref.ee.size());
    for (std::size_t i = 0; i < ref.vf.size(); ++i) {
      EXPECT_EQ(got.vf[i].vertex, ref.vf[i].vertex);
      EXPECT_EQ(got.vf[i].face, ref.vf[i].face);
      EXPECT_NEAR(got.vf[i].distance, ref.vf[i].distance, 1e-12);
    }
    for (std::size_t i = 0; i < ref.ee.size(); ++i) {
      EXPECT_EQ(got.ee[i].edge_a, ref.ee[i].edge_a);
      EXPECT_EQ(got.ee[i].edge_b, ref.ee[i].edge_b);
      EXPECT_NEAR(got.ee[i].distance, ref.ee[i].distance, 1e-12);
    }
  }
}

}  // namespace
}  // namespace clothcd
