// DetectOptions::cull_min_triangles: sound culling that tests only nodes of at least that many
// triangles (and refits cones for those only) reports exactly what the unculled detection
// reports, with a contact thickness, with kept pairs and the proximity query after them, over
// consecutive steps that move some vertices; only the culling counters change.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd::cull_threshold_test {
namespace {

// A gently waving grid sheet (nu x nv quads over [0, 1]^2) at `phase`: most of it can be culled.
research::ProceduralScene waving_sheet(int n, double phase, double motion) {
  research::ProceduralScene s;
  s.name = "waving sheet";
  s.num_vertices = (n + 1) * (n + 1);
  s.v_t0.resize(s.num_vertices, 3);
  s.v_t1.resize(s.num_vertices, 3);
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  auto at = [](double u, double v, double p) {
    return Eigen::Vector3d(u, v, 0.05 * std::sin(6 * u + p) * std::cos(5 * v));
  };
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double u = double(i) / n, v = double(j) / n;
      s.v_t0.row(id(i, j)) = at(u, v, phase).transpose();
      s.v_t1.row(id(i, j)) = at(u, v, phase + motion).transpose();
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      s.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return s;
}

// `v` with about a third of its vertices (a seeded choice) moved by up to `by` per axis.
Positions nudged(const Positions& v, double by, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0), d(-by, by);
  Positions out = v;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    if (u(rng) >= 1.0 / 3) continue;
    for (int k = 0; k < 3; ++k)
      out(i, k) += d(rng);
  }
  return out;
}

void expect_same(const ProximityResult& r, const ProximityResult& ref) {
  EXPECT_EQ(r.vf, ref.vf);
  EXPECT_EQ(r.ee, ref.ee);
}

TEST(CullMinTriangles, SameResultsAsNoCullingOverConsecutiveSteps) {
  const research::ProceduralScene scenes[] = {
      waving_sheet(24, 0.0, 0.3), research::crumpled_sheet(8, 7), research::twisted_strip(30, 3),
      research::stacked_sheets(6), research::winding_strip(40, 2)};
  std::uint64_t culled[2] = {0, 0};  // threshold 0, and the others
  for (const research::ProceduralScene& s : scenes) {
    for (const double thickness : {0.0, 1e-5, 1e-3}) {
      for (const double reuse : {0.0, 1e-3}) {
        DetectOptions o;
        o.build = BvhBuild::Patch;
        o.thickness = thickness;
        o.reuse_distance = reuse;
        SelfDetector none(s.faces, s.num_vertices, s.v_t0, o);
        for (const ConePolicy policy : {ConePolicy::Provot, ConePolicy::Proposed}) {
          for (const int min : {0, 2, 8, 32}) {
            SCOPED_TRACE(::testing::Message()
                         << s.name << " thickness " << thickness << " reuse " << reuse << " policy "
                         << int(policy) << " min " << min);
            DetectOptions c = o;
            c.culling = Culling::Sound;
            c.policy = policy;
            c.cull_min_triangles = min;
            SelfDetector det(s.faces, s.num_vertices, s.v_t0, c);
            Positions x0 = s.v_t0, x1 = s.v_t1;
            for (int step = 0; step < 3; ++step) {
              const DetectResult want = none.detect(x0, x1);
              const DetectResult got = det.detect(x0, x1);
              EXPECT_EQ(got.vf, want.vf) << "step " << step;
              EXPECT_EQ(got.ee, want.ee) << "step " << step;
              culled[min > 0 ? 1 : 0] += got.stats.nodes_culled;
              if (reuse > 0) {
                const Positions at = nudged(x1, 5e-4, step);
                expect_same(det.proximity(at, reuse), none.proximity(at, reuse));
              }
              x0 = x1;
              x1 = nudged(x1, 2e-3, 100 + step);
            }
          }
        }
      }
    }
  }
  EXPECT_GT(culled[0], 0u);
  EXPECT_GT(culled[1], 0u);  // the thresholds still cull
}

// Culled nodes all hold at least the threshold's triangles: a threshold above the root's size
// culls nothing, and the counters of the paper's rule are those of threshold 0.
TEST(CullMinTriangles, ThresholdBoundsTheTestedNodes) {
  const research::ProceduralScene s = waving_sheet(24, 0.0, 0.3);
  DetectOptions o;
  o.build = BvhBuild::Patch;
  o.culling = Culling::Sound;
  SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
  const DetectResult all = det.detect(s.v_t0, s.v_t1);
  EXPECT_GT(all.stats.nodes_culled, 0u);
  o.cull_min_triangles = 1;  // every internal node: the same cones and tests as 0
  det.set_options(o);
  const DetectResult one = det.detect(s.v_t0, s.v_t1);
  EXPECT_EQ(one.stats.nodes_culled, all.stats.nodes_culled);
  EXPECT_EQ(one.stats.cone_tests, all.stats.cone_tests);
  EXPECT_EQ(one.stats.contour_tests, all.stats.contour_tests);
  o.cull_min_triangles = static_cast<int>(s.faces.size()) + 1;
  det.set_options(o);
  const DetectResult none = det.detect(s.v_t0, s.v_t1);
  EXPECT_EQ(none.stats.nodes_culled, 0u);
  EXPECT_EQ(none.stats.cone_tests, 0u);
  EXPECT_EQ(none.vf, all.vf);
  EXPECT_EQ(none.ee, all.ee);
  o.cull_min_triangles = -1;
  EXPECT_THROW(det.set_options(o), InputError);
}

}  // namespace
}  // namespace clothcd::cull_threshold_test
