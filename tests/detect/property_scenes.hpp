#pragma once
// Seeded random scenes for the detector's property tests, and the checks against brute force.
//
// A scene is built in unit coordinates and then mapped to offset + scale * q: the scale is drawn
// log-uniformly from [1e-4, 1e4] and, in half of the scenes, the offset puts it about 1e5 from
// the origin (where a scene 1e-4 across is resolved to ~1e-7 of its size). Every scene mixes
// folding sheets and a sheet passing through them (so that there are collisions) with the
// degenerate input a simulator meets: slivers, zero-area triangles (collinear, two or three
// corners at one position), duplicate vertices (distinct ids at one position, in both frames),
// non-manifold edges (three or four triangles on one edge), duplicate faces, vertices on no
// face and vertices that do not move.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "clothcd/ccd/proximity.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/oracle.hpp"

namespace clothcd::test {

// Our own uniform conversion, so that a seed gives the same scene with every standard library.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : g_(seed) {}
  double uniform() { return static_cast<double>(g_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int integer(int lo, int hi) { return lo + static_cast<int>(g_() % std::uint64_t(hi - lo + 1)); }
  bool chance(double p) { return uniform() < p; }
  Eigen::Vector3d point() { return {uniform(), uniform(), uniform()}; }

 private:
  std::mt19937_64 g_;
};

struct RandomScene {
  std::vector<Face> faces;
  Positions v0, v1;  // t0 and t1 (n x 3)
  double scale = 1;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  [[nodiscard]] int nv() const { return static_cast<int>(v0.rows()); }
  [[nodiscard]] std::string describe() const {
    return "scale " + std::to_string(scale) + " offset (" + std::to_string(offset.x()) + ", " +
           std::to_string(offset.y()) + ", " + std::to_string(offset.z()) + "), " +
           std::to_string(faces.size()) + " faces, " + std::to_string(nv()) + " vertices";
  }
};

// The scene under construction, in unit coordinates.
struct UnitScene {
  std::vector<Face> faces;
  std::vector<Eigen::Vector3d> q0, q1;
  int add(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    q0.push_back(a);
    q1.push_back(b);
    return static_cast<int>(q0.size()) - 1;
  }
  int nv() const { return static_cast<int>(q0.size()); }
};

// An nx x ny sheet over [0, 1]^2 at height z; at t1 displaced by random waves of amplitude `amp`
// (large enough to fold a sheet of a few cells through itself) plus a drop `dz`.
inline void add_sheet(UnitScene& s, Rng& rng, int nx, int ny, double z, double amp, double dz) {
  const int base = s.nv();
  struct Wave {
    double kx, ky, phase, amp;
  };
  Wave w[3];
  for (auto& x : w)
    x = {2 * std::numbers::pi * rng.uniform(0.5, 2.0), 2 * std::numbers::pi * rng.uniform(0.5, 2.0),
         2 * std::numbers::pi * rng.uniform(), amp * rng.uniform(0.3, 1.0)};
  const double sx = rng.uniform(-0.3, 0.3) / nx, sy = rng.uniform(-0.3, 0.3) / ny;
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      const double x = double(i) / nx + sx, y = double(j) / ny + sy;
      const Eigen::Vector3d p(x, y, z + 0.02 * rng.uniform(-1, 1));
      Eigen::Vector3d d(w[0].amp * std::sin(w[0].kx * x + w[0].ky * y + w[0].phase),
                        w[1].amp * std::sin(w[1].kx * x + w[1].ky * y + w[1].phase),
                        w[2].amp * std::sin(w[2].kx * x + w[2].ky * y + w[2].phase) + dz);
      s.add(p, p + d);
    }
  }
  auto id = [&](int i, int j) { return base + i * (ny + 1) + j; };
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0) {
        s.faces.push_back({a, b, c});
        s.faces.push_back({a, c, d});
      } else {
        s.faces.push_back({a, b, d});
        s.faces.push_back({b, c, d});
      }
    }
  }
}

// A random vertex that lies on some face (the degeneracies attach to the surface).
inline int surface_vertex(const UnitScene& s, Rng& rng) {
  const Face& f = s.faces[rng.integer(0, static_cast<int>(s.faces.size()) - 1)];
  return f[rng.integer(0, 2)];
}

inline Eigen::Vector3d jitter(Rng& rng, double r) {
  return {rng.uniform(-r, r), rng.uniform(-r, r), rng.uniform(-r, r)};
}

// `size` controls the number of cells and soup triangles (unit tests: 1, sweeps: larger).
inline RandomScene random_scene(std::uint64_t seed, int size = 1, bool far_allowed = true) {
  Rng rng(seed);
  UnitScene s;
  // Folding sheets, and a flat sheet falling through the first one.
  const int sheets = rng.integer(1, 2);
  for (int k = 0; k < sheets; ++k) {
    add_sheet(s, rng, rng.integer(2, 3 + 2 * size), rng.integer(2, 3 + 2 * size), 0.5 + 0.1 * k,
              rng.uniform(0.1, 0.5), 0.0);
  }
  add_sheet(s, rng, rng.integer(1, 2 + size), rng.integer(1, 2 + size), 0.8, 0.02,
            -rng.uniform(0.3, 0.6));
  // Random soup triangles moving by up to 0.3.
  const int soup = rng.integer(2, 4 + 4 * size);
  for (int k = 0; k < soup; ++k) {
    const Eigen::Vector3d c = rng.point(), m = jitter(rng, 0.3);
    const double r = rng.uniform(0.05, 0.3);
    const int a = s.add(c + jitter(rng, r), c + jitter(rng, r) + m);
    const int b = s.add(c + jitter(rng, r), c + jitter(rng, r) + m);
    const int d = s.add(c + jitter(rng, r), c + jitter(rng, r) + m);
    s.faces.push_back({a, b, d});
  }
  const int degenerate = rng.integer(3, 6 + 3 * size);
  for (int k = 0; k < degenerate; ++k) {
    switch (rng.integer(0, 7)) {
      case 0: {  // sliver: the apex within 1e-9 of the base's line, in both frames
        const int a = surface_vertex(s, rng), b = surface_vertex(s, rng);
        if (a == b) break;
        const double t = rng.uniform(-0.5, 1.5);
        const int c = s.add(s.q0[a] + t * (s.q0[b] - s.q0[a]) + jitter(rng, 1e-9),
                            s.q1[a] + t * (s.q1[b] - s.q1[a]) + jitter(rng, 1e-9));
        s.faces.push_back({a, b, c});
        break;
      }
      case 1: {  // collinear corners (zero area up to rounding)
        const int a = surface_vertex(s, rng), b = surface_vertex(s, rng);
        if (a == b) break;
        const int c = s.add(0.5 * (s.q0[a] + s.q0[b]), 0.5 * (s.q1[a] + s.q1[b]));
        s.faces.push_back({a, c, b});
        break;
      }
      case 2: {  // two corners at one position: exactly zero area
        const int a = surface_vertex(s, rng), b = surface_vertex(s, rng);
        if (a == b) break;
        const int c = s.add(s.q0[a], s.q1[a]);
        s.faces.push_back({a, b, c});
        break;
      }
      case 3: {  // a triangle collapsed to a point, moving across the scene
        const Eigen::Vector3d p0 = rng.point(), p1 = rng.point();
        const int a = s.add(p0, p1), b = s.add(p0, p1), c = s.add(p0, p1);
        s.faces.push_back({a, b, c});
        break;
      }
      case 4: {  // duplicate vertex: a triangle hanging from a copy of a surface vertex
        const int v = surface_vertex(s, rng);
        const int w = s.add(s.q0[v], s.q1[v]);
        const int b = s.add(s.q0[v] + jitter(rng, 0.2), s.q1[v] + jitter(rng, 0.2));
        const int c = s.add(s.q0[v] + jitter(rng, 0.2), s.q1[v] + jitter(rng, 0.2));
        s.faces.push_back({w, b, c});
        break;
      }
      case 5: {  // non-manifold edge: one or two more triangles on an existing edge
        const Face f = s.faces[rng.integer(0, static_cast<int>(s.faces.size()) - 1)];
        const int e = rng.integer(0, 2);
        const int a = f[e], b = f[(e + 1) % 3];
        const int extra = rng.integer(1, 2);
        for (int x = 0; x < extra; ++x) {
          const Eigen::Vector3d m = 0.5 * (s.q0[a] + s.q0[b]);
          const Eigen::Vector3d m1 = 0.5 * (s.q1[a] + s.q1[b]);
          const Eigen::Vector3d d = jitter(rng, 0.3);
          const int c = s.add(m + d, m1 + d + jitter(rng, 0.1));
          s.faces.push_back(x % 2 == 0 ? Face{a, b, c} : Face{b, a, c});
        }
        break;
      }
      case 6: {  // duplicate face (same vertices, maybe flipped)
        const Face f = s.faces[rng.integer(0, static_cast<int>(s.faces.size()) - 1)];
        s.faces.push_back(rng.chance(0.5) ? f : Face{f[0], f[2], f[1]});
        break;
      }
      case 7: {  // a vertex on no face
        s.add(rng.point(), rng.point());
        break;
      }
    }
  }
  // Some vertices stand still (exactly zero motion).
  for (int v = 0; v < s.nv(); ++v) {
    if (rng.chance(0.1)) s.q1[v] = s.q0[v];
  }

  RandomScene out;
  out.faces = s.faces;
  out.scale = std::pow(10.0, rng.uniform(-4.0, 4.0));
  if (far_allowed && rng.chance(0.5)) {
    for (int k = 0; k < 3; ++k)
      out.offset[k] = (rng.chance(0.5) ? 1e5 : -1e5) * rng.uniform(1.0, 2.0);
  }
  out.v0.resize(s.nv(), 3);
  out.v1.resize(s.nv(), 3);
  for (int v = 0; v < s.nv(); ++v) {
    out.v0.row(v) = (out.offset + out.scale * s.q0[v]).transpose();
    out.v1.row(v) = (out.offset + out.scale * s.q1[v]).transpose();
  }
  return out;
}

// A copy of t1 in which every k-th surface vertex moved on by a further random amount (a second
// CCD pass after a response): the detector's kept boxes must follow.
inline Positions moved_some(const RandomScene& s, std::uint64_t seed) {
  Rng rng(seed ^ 0x9e3779b97f4a7c15ULL);
  Positions p = s.v1;
  for (int v = 0; v < s.nv(); ++v) {
    if (rng.chance(0.2)) {
      for (int k = 0; k < 3; ++k)
        p(v, k) += s.scale * rng.uniform(-0.2, 0.2);
    }
  }
  return p;
}

// ---- checks -------------------------------------------------------------------------------------

template <class C>
std::vector<std::pair<int, int>> vf_set(const C& c) {
  std::vector<std::pair<int, int>> r;
  for (const auto& x : c)
    r.emplace_back(x.vertex, x.face);
  return r;
}
template <class C>
std::vector<std::pair<int, int>> ee_set(const C& c) {
  std::vector<std::pair<int, int>> r;
  for (const auto& x : c)
    r.emplace_back(x.edge_a, x.edge_b);
  return r;
}

// The same VF and EE pairs (exactly), with times of impact within the kernels' tolerance.
template <class C>
void expect_same_collisions(const C& got, const C& want, double toi_tolerance, const char* what) {
  const auto key = [](const auto& x) {
    if constexpr (requires { x.vertex; }) {
      return std::pair(x.vertex, x.face);
    } else {
      return std::pair(x.edge_a, x.edge_b);
    }
  };
  std::vector<std::pair<int, int>> g, w;
  for (const auto& x : got)
    g.push_back(key(x));
  for (const auto& x : want)
    w.push_back(key(x));
  EXPECT_EQ(g, w) << what;
  if (g != w) return;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_NEAR(got[i].toi, want[i].toi, toi_tolerance) << what << " pair " << i;
    EXPECT_GE(got[i].toi, 0.0);
    EXPECT_LE(got[i].toi, 1.0);
  }
}

inline void expect_same(const DetectResult& got, const DetectResult& want, double tol) {
  expect_same_collisions(got.vf, want.vf, tol, "VF");
  expect_same_collisions(got.ee, want.ee, tol, "EE");
}

inline void expect_same(const PairDetectResult& got, const PairDetectResult& want, double tol) {
  expect_same_collisions(got.vf_a_on_b, want.vf_a_on_b, tol, "VF A on B");
  expect_same_collisions(got.vf_b_on_a, want.vf_b_on_a, tol, "VF B on A");
  expect_same_collisions(got.ee, want.ee, tol, "EE");
}

// Every VF pair (v on some face but not on f) and EE pair (no shared vertex) within h, by direct
// distance. Vertices on no face are not part of the surface (as for brute_force_detect).
inline ProximityResult surface_proximity(const Topology& t, const Positions& p, double h) {
  auto pt = [&](int v) { return Eigen::Vector3d(p.row(v).transpose()); };
  ProximityResult r;
  for (int v = 0; v < t.num_vertices(); ++v) {
    if (t.vertex_faces(v).empty()) continue;
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

inline void expect_same(const ProximityResult& got, const ProximityResult& want) {
  std::vector<std::pair<int, int>> g, w;
  for (const auto& x : got.vf)
    g.emplace_back(x.vertex, x.face);
  for (const auto& x : want.vf)
    w.emplace_back(x.vertex, x.face);
  EXPECT_EQ(g, w) << "proximity VF";
  if (g == w) {
    for (std::size_t i = 0; i < got.vf.size(); ++i)
      EXPECT_EQ(got.vf[i].distance, want.vf[i].distance) << "proximity VF pair " << i;
  }
  g.clear();
  w.clear();
  for (const auto& x : got.ee)
    g.emplace_back(x.edge_a, x.edge_b);
  for (const auto& x : want.ee)
    w.emplace_back(x.edge_a, x.edge_b);
  EXPECT_EQ(g, w) << "proximity EE";
  if (g == w) {
    for (std::size_t i = 0; i < got.ee.size(); ++i)
      EXPECT_EQ(got.ee[i].distance, want.ee[i].distance) << "proximity EE pair " << i;
  }
}

// The detector configurations that claim to find exactly what brute force finds.
struct Config {
  Culling culling;
  ConePolicy policy;
  BvhBuild build;
};
// With thickness > 0 Sound uses no cones, so the cone policy does not matter there.
inline std::vector<Config> exact_configs(double thickness) {
  std::vector<Config> c;
  for (BvhBuild b : {BvhBuild::Spatial, BvhBuild::Patch}) {
    c.push_back({Culling::None, ConePolicy::Proposed, b});
    for (ConePolicy p : {ConePolicy::Provot, ConePolicy::Proposed, ConePolicy::Exact}) {
      if (thickness == 0 || p == ConePolicy::Exact) c.push_back({Culling::Sound, p, b});
    }
  }
  return c;
}

inline std::string describe(const Config& c, double thickness) {
  return "culling " + std::to_string(int(c.culling)) + " policy " + std::to_string(int(c.policy)) +
         " build " + std::to_string(int(c.build)) + " thickness " + std::to_string(thickness);
}

// The contact distance of the thick checks, relative to the scene's scale. The thick kernels cost
// about a millisecond a query, so those checks run on smaller scenes.
constexpr double kThickness = 0.02;

// detect() of every exact configuration at the given thickness (relative to the scene's scale)
// equals brute force: on the step, then on a second pass with some end positions changed (the
// kept boxes and refit follow), and after a proximity query in between. Returns the number of
// collisions brute force found.
inline std::size_t check_self_detect(const RandomScene& s, std::uint64_t seed,
                                     double relative_thickness) {
  const Topology topo(s.faces, s.nv());
  const Positions v1b = moved_some(s, seed);
  std::size_t found = 0;
  {
    const double thickness = relative_thickness * s.scale;
    DetectOptions base;
    base.thickness = thickness;
    const DetectResult ref = research::brute_force_detect(topo, s.v0, s.v1, base);
    const DetectResult ref_b = research::brute_force_detect(topo, s.v0, v1b, base);
    found += ref.vf.size() + ref.ee.size();
    for (const Config& c : exact_configs(thickness)) {
      SCOPED_TRACE(describe(c, thickness));
      DetectOptions o = base;
      o.culling = c.culling;
      o.policy = c.policy;
      o.build = c.build;
      SelfDetector det(s.faces, s.nv(), s.v0, o);
      {
        SCOPED_TRACE("first pass");
        expect_same(det.detect(s.v0, s.v1), ref, o.toi_tolerance);
      }
      {
        SCOPED_TRACE("second pass, some end positions changed");
        expect_same(det.detect(s.v0, v1b), ref_b, o.toi_tolerance);
      }
      (void)det.proximity(s.v0, 0.05 * s.scale);
      {
        SCOPED_TRACE("after a proximity query");
        expect_same(det.detect(s.v0, s.v1), ref, o.toi_tolerance);
      }
    }
  }
  return found;
}

// proximity() equals the all-pairs distances for h = 0 and h > 0, with both builds; and with a
// detector that keeps its pairs for reuse, right after detect() and after some vertices moved.
inline std::size_t check_proximity(const RandomScene& s, std::uint64_t seed) {
  const Topology topo(s.faces, s.nv());
  const Positions later = moved_some(s, seed + 1);
  std::size_t found = 0;
  for (double h : {0.0, 0.05 * s.scale}) {
    const ProximityResult at_t1 = surface_proximity(topo, s.v1, h);
    const ProximityResult at_later = surface_proximity(topo, later, h);
    found += at_t1.vf.size() + at_t1.ee.size();
    for (BvhBuild b : {BvhBuild::Spatial, BvhBuild::Patch}) {
      SCOPED_TRACE("h " + std::to_string(h) + " build " + std::to_string(int(b)));
      DetectOptions o;
      o.build = b;
      SelfDetector det(s.faces, s.nv(), s.v0, o);
      expect_same(det.proximity(s.v1, h), at_t1);
      o.reuse_distance = 0.05 * s.scale;
      SelfDetector keep(s.faces, s.nv(), s.v0, o);
      (void)keep.detect(s.v0, s.v1);
      {
        SCOPED_TRACE("reusing the detection's pairs");
        expect_same(keep.proximity(s.v1, h), at_t1);
        expect_same(keep.proximity(later, h), at_later);
      }
    }
  }
  return found;
}

// PairDetector between two scenes at the same scale and place equals brute force, both builds,
// at the given thickness (relative to the scale). Returns the number of collisions brute force
// found.
inline std::size_t check_pair_detect(const RandomScene& a, const RandomScene& b,
                                     double relative_thickness) {
  const Topology ta(a.faces, a.nv()), tb(b.faces, b.nv());
  std::size_t found = 0;
  {
    const double thickness = relative_thickness * a.scale;
    DetectOptions o;
    o.thickness = thickness;
    const PairDetectResult ref =
        research::brute_force_detect_pair(ta, a.v0, a.v1, tb, b.v0, b.v1, o);
    found += ref.vf_a_on_b.size() + ref.vf_b_on_a.size() + ref.ee.size();
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      SCOPED_TRACE("pair build " + std::to_string(int(build)) + " thickness " +
                   std::to_string(thickness));
      o.build = build;
      PairDetector det(a.faces, a.nv(), a.v0, b.faces, b.nv(), b.v0, o);
      expect_same(det.detect(a.v0, a.v1, b.v0, b.v1), ref, o.toi_tolerance);
    }
  }
  return found;
}

// The second mesh of a pair scene: another random scene moved to the first one's scale and place.
inline RandomScene partner(const RandomScene& a, std::uint64_t seed, int size = 1) {
  RandomScene b = random_scene(seed, size, false);
  const double k = a.scale / b.scale;
  for (Positions* p : {&b.v0, &b.v1}) {
    for (int v = 0; v < b.nv(); ++v)
      p->row(v) = (a.offset + k * p->row(v).transpose()).transpose();
  }
  b.scale = a.scale;
  b.offset = a.offset;
  return b;
}

}  // namespace clothcd::test
