#pragma once
// Small two-mesh scenes and result helpers shared by the detector API tests.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <span>
#include <vector>

#include "clothcd/ccd/proximity.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/oracle.hpp"

namespace clothcd::test {

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

inline Mesh sheet(int n) {
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
inline Mesh ball(int k, double r, const Eigen::Vector3d& c0, const Eigen::Vector3d& c1) {
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

inline void expect_pair_equal(const PairDetectResult& r, const PairDetectResult& ref) {
  EXPECT_EQ(vf_pairs(r.vf_a_on_b), vf_pairs(ref.vf_a_on_b));
  EXPECT_EQ(vf_pairs(r.vf_b_on_a), vf_pairs(ref.vf_b_on_a));
  EXPECT_EQ(ee_pairs(r.ee), ee_pairs(ref.ee));
  EXPECT_EQ(r.vf_a_on_b, ref.vf_a_on_b);  // same kernels: same times of impact too
  EXPECT_EQ(r.vf_b_on_a, ref.vf_b_on_a);
  EXPECT_EQ(r.ee, ref.ee);
}

// A short step: the ball's lower half passes the sheet (a simulator step, not a fall).
inline void check_pair_detector(double thickness) {
  const Mesh a = sheet(8);
  const Mesh b = ball(2, 0.18, {0.47, 0.52, 0.2}, {0.5, 0.49, 0.05});
  const Topology ta(a.faces, a.nv()), tb(b.faces, b.nv());
  DetectOptions o;
  o.thickness = thickness;
  const PairDetectResult ref = research::brute_force_detect_pair(ta, a.v0, a.v1, tb, b.v0, b.v1, o);
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

// Every VF pair (v not on f) and EE pair (no shared vertex) within h, by direct distance.
// `links`: DetectOptions::linked_vertices, whose pairs are left out (any order).
inline ProximityResult brute_force_proximity(const Topology& t, const Positions& p, double h,
                                             std::span<const std::pair<int, int>> links = {}) {
  auto pt = [&](int v) { return Eigen::Vector3d(p.row(v).transpose()); };
  auto linked = [&](int u, int w) {
    for (auto [a, b] : links) {
      if ((a == u && b == w) || (a == w && b == u)) return true;
    }
    return false;
  };
  ProximityResult r;
  for (int v = 0; v < t.num_vertices(); ++v) {
    for (int f = 0; f < t.num_faces(); ++f) {
      const Face& x = t.faces()[f];
      if (v == x[0] || v == x[1] || v == x[2]) continue;
      if (linked(v, x[0]) || linked(v, x[1]) || linked(v, x[2])) continue;
      const double d = point_triangle_proximity(pt(v), pt(x[0]), pt(x[1]), pt(x[2])).distance;
      if (d <= h) r.vf.push_back({v, f, d});
    }
  }
  for (int a = 0; a < t.num_edges(); ++a) {
    for (int b = a + 1; b < t.num_edges(); ++b) {
      const Edge &ea = t.edges()[a], &eb = t.edges()[b];
      if (ea[0] == eb[0] || ea[0] == eb[1] || ea[1] == eb[0] || ea[1] == eb[1]) continue;
      if (linked(ea[0], eb[0]) || linked(ea[0], eb[1]) || linked(ea[1], eb[0]) ||
          linked(ea[1], eb[1])) {
        continue;
      }
      const double d = edge_edge_proximity(pt(ea[0]), pt(ea[1]), pt(eb[0]), pt(eb[1])).distance;
      if (d <= h) r.ee.push_back({a, b, d});
    }
  }
  return r;
}

}  // namespace clothcd::test
