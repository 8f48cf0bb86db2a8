// The detector API against brute force on small scenes: two-mesh detection (a sheet and a closed
// box-like mesh moving through it), proximity queries against an all-feature-pairs distance oracle,
// active-face restriction, thickness > 0; and determinism of results and counters on 1, 2 and 4
// threads, for self and pair detection.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include "clothcd/ccd/proximity.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/oracle.hpp"
#include "clothcd/detect/procedural.hpp"

namespace clothcd {
namespace {

template <class C>
std::vector<std::pair<int, int>> vf_pairs(const C& c) {
  std::vector<std::pair<int, int>> s;
  for (const auto& x : c)
    s.emplace_back(x.vertex, x.face);
  return s;
}
template <class C>
std::vector<std::pair<int, int>> ee_pairs(const C& c) {
  std::vector<std::pair<int, int>> s;
  for (const auto& x : c)
    s.emplace_back(x.edge_a, x.edge_b);
  return s;
}

// A wavy n x n sheet on [0,1]^2 at height ~0 (garment-like: one panel, gentle folds).
struct Mesh {
  std::vector<Face> faces;
  Positions v0, v1;
  int nv() const { return static_cast<int>(v0.rows()); }
};

Mesh sheet(int n) {
  Mesh m;
  m.v0.resize((n + 1) * (n + 1), 3);
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const double x = double(i) / n, y = double(j) / n;
      m.v0.row(i * (n + 1) + j) << x, y, 0.03 * std::sin(5 * x) * std::cos(4 * y);
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j, b = a + n + 1;
      m.faces.push_back({a, b, b + 1});
      m.faces.push_back({a, b + 1, a + 1});
    }
  }
  m.v1 = m.v0;
  for (int v = 0; v < m.nv(); ++v)
    m.v1(v, 2) += 0.01 * std::sin(7.0 * m.v0(v, 0) + 3.0 * m.v0(v, 1));  // a slight flutter
  return m;
}

// A closed, inflated cube (a box mesh, k x k quads per side, pushed towards a sphere) of radius
// r at `c0`, moving to `c1`.
Mesh ball(int k, double r, const Eigen::Vector3d& c0, const Eigen::Vector3d& c1) {
  Mesh m;
  std::vector<Eigen::Vector3d> pts;
  std::map<std::array<int, 3>, int> id;
  auto vertex = [&](const std::array<int, 3>& g) {
    auto [it, added] = id.emplace(g, static_cast<int>(pts.size()));
    if (added) {
      const Eigen::Vector3d p(2.0 * g[0] / k - 1, 2.0 * g[1] / k - 1, 2.0 * g[2] / k - 1);
      pts.push_back(r * (0.5 * p + 0.5 * p.normalized()));
    }
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side <= 1; ++side) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int i = 0; i < k; ++i) {
        for (int j = 0; j < k; ++j) {
          auto g = [&](int a, int b) {
            std::array<int, 3> c{};
            c[axis] = side * k;
            c[u] = a;
            c[w] = b;
            return vertex(c);
          };
          const int p00 = g(i, j), p10 = g(i + 1, j), p11 = g(i + 1, j + 1), p01 = g(i, j + 1);
          // Outward orientation on both sides.
          if (side == 1) {
            m.faces.push_back({p00, p10, p11});
            m.faces.push_back({p00, p11, p01});
          } else {
            m.faces.push_back({p00, p11, p10});
            m.faces.push_back({p00, p01, p11});
          }
        }
      }
    }
  }
  m.v0.resize(static_cast<Eigen::Index>(pts.size()), 3);
  m.v1.resize(static_cast<Eigen::Index>(pts.size()), 3);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    m.v0.row(static_cast<Eigen::Index>(i)) = (pts[i] + c0).transpose();
    m.v1.row(static_cast<Eigen::Index>(i)) = (pts[i] + c1).transpose();
  }
  return m;
}

void expect_pair_equal(const PairDetectResult& r, const PairDetectResult& ref) {
  EXPECT_EQ(vf_pairs(r.vf_a_on_b), vf_pairs(ref.vf_a_on_b));
  EXPECT_EQ(vf_pairs(r.vf_b_on_a), vf_pairs(ref.vf_b_on_a));
  EXPECT_EQ(ee_pairs(r.ee), ee_pairs(ref.ee));
  EXPECT_EQ(r.vf_a_on_b, ref.vf_a_on_b);  // same kernels: same times of impact too
  EXPECT_EQ(r.vf_b_on_a, ref.vf_b_on_a);
  EXPECT_EQ(r.ee, ref.ee);
}

TEST(DetectApi, PairDetectorEqualsBruteForce) {
  // A short step: the ball's lower half passes the sheet (a simulator step, not a fall).
  const Mesh a = sheet(10);
  const Mesh b = ball(3, 0.18, {0.47, 0.52, 0.2}, {0.5, 0.49, 0.05});
  const Topology ta(a.faces, a.nv()), tb(b.faces, b.nv());
  for (double thickness : {0.0, 0.003}) {
    DetectOptions o;
    o.thickness = thickness;
    const PairDetectResult ref = brute_force_detect_pair(ta, a.v0, a.v1, tb, b.v0, b.v1, o);
    EXPECT_GT(ref.vf_a_on_b.size(), 0u);
    EXPECT_GT(ref.vf_b_on_a.size(), 0u);
    EXPECT_GT(ref.ee.size(), 0u);
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      SCOPED_TRACE(::testing::Message() << "thickness " << thickness << " build " << int(build));
      o.build = build;
      PairDetector det(a.faces, a.nv(), a.v0, b.faces, b.nv(), b.v0, o);
      expect_pair_equal(det.detect(a.v0, a.v1, b.v0, b.v1), ref);
    }
  }
}

// Every VF pair (v not on f) and EE pair (no shared vertex) within h, by direct distance.
ProximityResult brute_force_proximity(const Topology& t, const Positions& p, double h) {
  auto pt = [&](int v) { return Eigen::Vector3d(p.row(v).transpose()); };
  ProximityResult r;
  for (int v = 0; v < t.num_vertices(); ++v) {
    for (int f = 0; f < t.num_faces(); ++f) {
      const Face& x = t.faces()[f];
      if (v == x[0] || v == x[1] || v == x[2]) continue;
      const double d = point_triangle_proximity(pt(v), pt(x[0]), pt(x[1]), pt(x[2])).distance;
      if (d <= h) r.vf.push_back({v, f, d});
    }
  }
  for (int a = 0; a < t.num_edges(); ++a) {
    for (int b = a + 1; b < t.num_edges(); ++b) {
      const Edge &ea = t.edges()[a], &eb = t.edges()[b];
      if (ea[0] == eb[0] || ea[0] == eb[1] || ea[1] == eb[0] || ea[1] == eb[1]) continue;
      const double d = edge_edge_proximity(pt(ea[0]), pt(ea[1]), pt(eb[0]), pt(eb[1])).distance;
      if (d <= h) r.ee.push_back({a, b, d});
    }
  }
  return r;
}

TEST(DetectApi, ProximityEqualsAllPairsDistance) {
  for (const auto& s : {crumpled_sheet(10, 2), twisted_strip(40, 3), stacked_sheets(8)}) {
    const Topology topo(s.faces, s.num_vertices);
    // A folded state (the end of the motion), where features come close.
    const Positions v = 0.5 * (s.v_t0 + s.v_t1);
    for (double h : {0.0, 0.01, 0.05}) {
      for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
        SCOPED_TRACE(::testing::Message() << s.name << " h " << h << " build " << int(build));
        DetectOptions o;
        o.build = build;
        o.culling = Culling::Sound;  // must be ignored: proximity never culls by cones
        SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
        const ProximityResult r = det.proximity(v, h);
        const ProximityResult ref = brute_force_proximity(topo, v, h);
        if (h > 0) EXPECT_GT(ref.vf.size() + ref.ee.size(), 0u);
        EXPECT_EQ(vf_pairs(r.vf), vf_pairs(ref.vf));
        EXPECT_EQ(ee_pairs(r.ee), ee_pairs(ref.ee));
        for (std::size_t i = 0; i < std::min(r.vf.size(), ref.vf.size()); ++i)
          EXPECT_EQ(r.vf[i].distance, ref.vf[i].distance);
      }
    }
  }
}

TEST(DetectApi, ActiveFacesEqualFilteredBruteForce) {
  for (const auto& s : {crumpled_sheet(12, 3), twisted_strip(50, 4)}) {
    const Topology topo(s.faces, s.num_vertices);
    // Every third face, and a contiguous block: both sparse and clustered sets.
    std::vector<int> active;
    std::vector<std::uint8_t> mask(topo.num_faces(), 0);
    for (int f = 0; f < topo.num_faces(); ++f) {
      if (f % 3 == 0 || (f > topo.num_faces() / 2 && f < topo.num_faces() / 2 + 40)) {
        active.push_back(f);
        mask[f] = 1;
      }
    }
    const DetectResult full = brute_force_detect(topo, s.v_t0, s.v_t1);
    const DetectResult ref = brute_force_detect(topo, s.v_t0, s.v_t1, {}, mask);
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
        det.set_active_faces(active);
        const DetectResult r = det.detect(s.v_t0, s.v_t1);
        EXPECT_EQ(r.vf, ref.vf);
        EXPECT_EQ(r.ee, ref.ee);
        det.clear_active_faces();
        const DetectResult all = det.detect(s.v_t0, s.v_t1);
        EXPECT_EQ(all.vf, full.vf);
        EXPECT_EQ(all.ee, full.ee);
      }
    }
  }
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

// Every counter of a detection (times excluded).
std::vector<std::uint64_t> counters(const DetectStats& s) {
  return {s.box_tests,
          s.nodes_culled,
          s.cone_tests,
          s.contour_tests,
          s.contour_fails,
          std::uint64_t(s.internal_nodes),
          std::uint64_t(s.connected_internal_nodes),
          std::uint64_t(s.disk_internal_nodes),
          s.adjacent_pairs,
          s.triangle_pairs,
          s.vf_tests,
          s.ee_tests,
          s.vf_np_culled,
          s.ee_np_culled,
          s.vf_orphans,
          s.ee_orphans,
          s.vf_collisions,
          s.ee_collisions};
}

TEST(DetectApi, DeterministicOnOneTwoAndFourThreads) {
  const ProceduralScene s = crumpled_sheet(16, 5);
  const Mesh a = sheet(10);
  const Mesh b = ball(3, 0.18, {0.47, 0.52, 0.2}, {0.5, 0.49, 0.05});
  for (Culling culling : {Culling::None, Culling::Cone, Culling::Sound}) {
    DetectOptions o;
    o.build = BvhBuild::Patch;
    o.culling = culling;
    std::optional<DetectResult> first;
    std::optional<PairDetectResult> first_pair;
    for (int threads : {1, 2, 4}) {
      SCOPED_TRACE(::testing::Message() << "culling " << int(culling) << " threads " << threads);
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      const DetectResult r = det.detect(s.v_t0, s.v_t1);
      PairDetector pd(a.faces, a.nv(), a.v0, b.faces, b.nv(), b.v0, o);
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

}  // namespace
}  // namespace clothcd
