// The candidates stage against the detector: the library's kernels run on the candidates of all
// overlapping leaf pairs report exactly SelfDetector::detect()'s VF and EE collisions, the
// candidates whose swept boxes overlap are as many as the detector's tests, and every feature
// pair comes from one triangle pair at most.

#include "clothcd/detect/candidates.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <set>
#include <vector>

#include "clothcd/bvh/aabb.hpp"
#include "clothcd/bvh/traverse.hpp"
#include "clothcd/ccd/queries.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/procedural.hpp"

// Helpers in a namespace of their own: the tests of a folder may share one translation unit.
namespace clothcd::candidates_test {
namespace {

Eigen::Vector3d row(const Positions& p, int i) {
  return p.row(i).transpose();
}

// The kernels with the detector's settings on every candidate, sorted as the detector sorts.
DetectResult run_kernels(const Topology& topo, const Positions& x0, const Positions& x1,
                         const FeaturePairs& pairs, const DetectOptions& o) {
  CcdOptions ccd;
  ccd.thickness = o.thickness;
  ccd.fast_path = o.fast_path;
  ccd.toi_tolerance = o.toi_tolerance;
  DetectResult r;
  for (auto [v, f] : pairs.vf) {
    const Face& t = topo.faces()[f];
    const VertexFaceQuery q{row(x0, v), row(x0, t[0]), row(x0, t[1]), row(x0, t[2]),
                            row(x1, v), row(x1, t[0]), row(x1, t[1]), row(x1, t[2])};
    const CcdResult c = vertex_face_ccd(q, ccd);
    if (c.hit) r.vf.push_back({v, f, t, c.toi});
  }
  for (auto [ea, eb] : pairs.ee) {
    const Edge &a = topo.edges()[ea], &b = topo.edges()[eb];
    const EdgeEdgeQuery q{row(x0, a[0]), row(x0, a[1]), row(x0, b[0]), row(x0, b[1]),
                          row(x1, a[0]), row(x1, a[1]), row(x1, b[0]), row(x1, b[1])};
    const CcdResult c = edge_edge_ccd(q, ccd);
    if (c.hit) r.ee.push_back({ea, eb, a, b, c.toi});
  }
  return r;  // candidates are sorted, so the hits are too
}

TEST(Candidates, KernelsOnTheCandidatesFindWhatTheDetectorFinds) {
  for (const auto& s : {research::crumpled_sheet(24, 5), research::twisted_strip(80, 4),
                        research::winding_strip(96, 3), research::stacked_sheets(10)}) {
    const Topology topo(s.faces, s.num_vertices);
    for (bool linked : {false, true}) {
      SCOPED_TRACE(::testing::Message() << s.name << " linked " << linked);
      DetectOptions o;
      o.culling = Culling::None;
      o.distance_filter = false;  // every overlapping feature pair reaches the feature tests
      if (linked) {               // link some vertices far apart in the mesh, as seams do
        for (int v = 0; v + 7 < s.num_vertices; v += 13)
          o.linked_vertices.emplace_back(v, s.num_vertices - 1 - v);
      }
      SelfDetector detector(s.faces, s.num_vertices, s.v_t0, o);
      const DetectResult expected = detector.detect(s.v_t0, s.v_t1);
      ASSERT_FALSE(expected.vf.empty() && expected.ee.empty());

      const Candidates candidates(topo, o.linked_vertices);
      const auto triangle_pairs = overlapping_leaf_pairs(detector.bvh());
      const FeaturePairs all = candidates(triangle_pairs);
      // The detector tests exactly the candidates whose swept feature boxes overlap.
      // Of them, those the filters cull with DetectOptions::distance_filter: the NP filter, and
      // the distance filter (two bisections) on what the NP filter keeps.
      std::uint64_t vf_tests = 0, ee_tests = 0, vf_filtered = 0, ee_filtered = 0;
      const auto filtered = [](const auto& q) {
        return np_filter_culls(q) || distance_filter_culls(q, 0.0, 2);
      };
      for (auto [v, f] : all.vf) {
        const Face& t = topo.faces()[f];
        const Eigen::Vector3d p0 = row(s.v_t0, v), p1 = row(s.v_t1, v);
        const Eigen::Vector3d a0 = row(s.v_t0, t[0]), b0 = row(s.v_t0, t[1]),
                              c0 = row(s.v_t0, t[2]), a1 = row(s.v_t1, t[0]),
                              b1 = row(s.v_t1, t[1]), c1 = row(s.v_t1, t[2]);
        if (!overlap(swept_feature_box({&p0, &p1}, 0.0),
                     swept_feature_box({&a0, &b0, &c0, &a1, &b1, &c1}, 0.0))) {
          continue;
        }
        ++vf_tests;
        vf_filtered += filtered(VertexFaceQuery{p0, a0, b0, c0, p1, a1, b1, c1});
      }
      for (auto [ea, eb] : all.ee) {
        const Edge &a = topo.edges()[ea], &b = topo.edges()[eb];
        const Eigen::Vector3d a00 = row(s.v_t0, a[0]), a01 = row(s.v_t0, a[1]),
                              a10 = row(s.v_t1, a[0]), a11 = row(s.v_t1, a[1]);
        const Eigen::Vector3d b00 = row(s.v_t0, b[0]), b01 = row(s.v_t0, b[1]),
                              b10 = row(s.v_t1, b[0]), b11 = row(s.v_t1, b[1]);
        if (!overlap(swept_feature_box({&a00, &a01, &a10, &a11}, 0.0),
                     swept_feature_box({&b00, &b01, &b10, &b11}, 0.0))) {
          continue;
        }
        ++ee_tests;
        ee_filtered += filtered(EdgeEdgeQuery{a00, a01, b00, b01, a10, a11, b10, b11});
      }
      EXPECT_EQ(vf_tests, expected.stats.vf_tests);
      EXPECT_EQ(ee_tests, expected.stats.ee_tests);
      const DetectResult got = run_kernels(topo, s.v_t0, s.v_t1, all, o);
      EXPECT_EQ(got.vf, expected.vf);
      EXPECT_EQ(got.ee, expected.ee);
      // With the distance filter the whole-triangle bound first drops triangle pairs that never
      // touch, then the feature bound culls what the NP filter keeps: the same collisions from
      // fewer feature tests. Each feature pair of a dropped triangle pair is one the feature
      // bound culls, so the dropped tests and the culls add up to the filters' culls above.
      DetectOptions with = o;
      with.distance_filter = true;
      SelfDetector filtering(s.faces, s.num_vertices, s.v_t0, with);
      const DetectResult f = filtering.detect(s.v_t0, s.v_t1);
      EXPECT_EQ(f.vf, expected.vf);
      EXPECT_EQ(f.ee, expected.ee);
      EXPECT_GT(f.stats.triangle_pairs_apart, 0u);
      EXPECT_LT(f.stats.vf_tests + f.stats.ee_tests, vf_tests + ee_tests);
      EXPECT_EQ(vf_tests - f.stats.vf_tests + f.stats.vf_np_culled, vf_filtered);
      EXPECT_EQ(ee_tests - f.stats.ee_tests + f.stats.ee_np_culled, ee_filtered);
      EXPECT_GT(vf_filtered + ee_filtered,
                expected.stats.vf_np_culled + expected.stats.ee_np_culled);

      // Each feature pair once: per triangle pair, unsorted, no repeats, none an orphan.
      FeaturePairs owned;
      for (auto [f, g] : triangle_pairs)
        candidates.append(f, g, owned);
      const std::set<std::pair<int, int>> vf(owned.vf.begin(), owned.vf.end());
      const std::set<std::pair<int, int>> ee(owned.ee.begin(), owned.ee.end());
      EXPECT_EQ(vf.size(), owned.vf.size());
      EXPECT_EQ(ee.size(), owned.ee.size());
      EXPECT_EQ(vf.size() + candidates.orphans().vf.size(), all.vf.size());
      EXPECT_EQ(ee.size() + candidates.orphans().ee.size(), all.ee.size());
      for (auto [a, b] : owned.ee)
        EXPECT_LT(a, b);
    }
  }
}

TEST(Candidates, PairsSharingAVertexYieldNothingAndOrderDoesNotMatter) {
  const research::ProceduralScene s = research::crumpled_sheet(6, 2);
  const Topology topo(s.faces, s.num_vertices);
  const Candidates c(topo);
  for (int f = 0; f < topo.num_faces(); ++f) {
    for (int g = 0; g < topo.num_faces(); ++g) {
      FeaturePairs fg, gf;
      c.append(f, g, fg);
      c.append(g, f, gf);
      std::sort(fg.vf.begin(), fg.vf.end());
      std::sort(gf.vf.begin(), gf.vf.end());
      std::sort(fg.ee.begin(), fg.ee.end());
      std::sort(gf.ee.begin(), gf.ee.end());
      EXPECT_EQ(fg, gf);
      if (topo.faces_share_vertex(f, g)) {
        EXPECT_TRUE(fg.vf.empty() && fg.ee.empty());
      }
    }
  }
  // Listing a pair twice adds nothing.
  const std::vector<std::pair<int, int>> once{{0, 30}}, twice{{0, 30}, {30, 0}, {0, 30}};
  EXPECT_EQ(c(once), c(twice));
  FeaturePairs sink;
  EXPECT_THROW(c.append(0, topo.num_faces(), sink), InputError);
  const std::vector<std::pair<int, int>> bad_link{{0, s.num_vertices}};
  EXPECT_THROW(Candidates(topo, bad_link), InputError);
}

}  // namespace
}  // namespace clothcd::candidates_test
