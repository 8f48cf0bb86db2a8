// The earliest-impact query against brute force: every VF and EE pair through the kernels at
// the query's tolerance (the earliest of them is the reference), the exact rational oracle at
// zero thickness (no pair touches before the reported time), scenes with a known contact time,
// links, restrictions, two meshes, thread counts and the windows.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "clothcd/ccd/proximity.hpp"
#include "clothcd/ccd/queries.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "detect/earliest.hpp"
#include "exact_oracle.hpp"
#include "property_scenes.hpp"

namespace clothcd {
namespace earliest_test {

using Kind = EarliestImpact::Kind;
using test::RandomScene;

bool shares(const Face& f, int v) {
  return f[0] == v || f[1] == v || f[2] == v;
}

VertexFaceQuery vf_query(const Positions& a0, const Positions& a1, int v, const Positions& b0,
                         const Positions& b1, const Face& t) {
  return {a0.row(v), b0.row(t[0]), b0.row(t[1]), b0.row(t[2]),
          a1.row(v), b1.row(t[0]), b1.row(t[1]), b1.row(t[2])};
}
EdgeEdgeQuery ee_query(const Positions& a0, const Positions& a1, const Edge& p, const Positions& b0,
                       const Positions& b1, const Edge& q) {
  return {a0.row(p[0]), a0.row(p[1]), b0.row(q[0]), b0.row(q[1]),
          a1.row(p[0]), a1.row(p[1]), b1.row(q[0]), b1.row(q[1])};
}

// The windows searched: [0, first], then each kWindowGrowth times longer up to 1; the search
// stops at the first that holds a time by its end. (The time may come before the window: the
// kernels may time a pair that comes within their certified distance earlier, which the earlier
// windows' filters, at the thickness itself, rightly left out.)
void expect_windows(const EarliestImpact& e, const std::string& what) {
  std::vector<double> ends;
  for (double hi = e.first_window;; hi = std::min(1.0, hi * detail::kWindowGrowth)) {
    ends.push_back(hi);
    if (hi == 1.0) break;
  }
  ASSERT_GE(e.windows, 1) << what;
  ASSERT_LE(e.windows, static_cast<int>(ends.size())) << what;
  const auto k = static_cast<std::size_t>(e.windows);
  if (e.kind == Kind::None) {
    EXPECT_EQ(k, ends.size()) << what;
    return;
  }
  EXPECT_LE(e.toi, ends[k - 1]) << what;
}

// The earliest kernel hit over every pair that `keep` admits, ties by (kind, ids), as the query
// orders them. `self`: one mesh (pairs sharing a vertex skipped, each EE pair once).
struct Brute {
  EarliestImpact best;
  void offer(double toi, Kind kind, int a, int b, bool on_b) {
    const auto key = [](const EarliestImpact& e) {
      return std::tuple(e.toi, e.kind == Kind::None, e.kind, e.vertex_on_b, e.ids);
    };
    EarliestImpact e;
    e.toi = toi;
    e.kind = kind;
    e.ids = {a, b};
    e.vertex_on_b = on_b;
    if (key(e) < key(best)) best = e;
  }
};

template <class KeepVf, class KeepEe>
EarliestImpact brute_self(const Topology& t, const Positions& x0, const Positions& x1,
                          const CcdOptions& o, KeepVf&& keep_vf, KeepEe&& keep_ee) {
  Brute b;
  for (int v = 0; v < t.num_vertices(); ++v) {
    for (int f = 0; f < t.num_faces(); ++f) {
      const Face& face = t.faces()[f];
      if (shares(face, v) || !keep_vf(v, f)) continue;
      const CcdResult r = vertex_face_ccd(vf_query(x0, x1, v, x0, x1, face), o);
      if (r.hit) b.offer(r.toi, Kind::VertexFace, v, f, false);
    }
  }
  const auto& edges = t.edges();
  for (int i = 0; i < t.num_edges(); ++i) {
    for (int j = i + 1; j < t.num_edges(); ++j) {
      const Edge &p = edges[i], &q = edges[j];
      if (p[0] == q[0] || p[0] == q[1] || p[1] == q[0] || p[1] == q[1] || !keep_ee(i, j)) continue;
      const CcdResult r = edge_edge_ccd(ee_query(x0, x1, p, x0, x1, q), o);
      if (r.hit) b.offer(r.toi, Kind::EdgeEdge, i, j, false);
    }
  }
  return b.best;
}

EarliestImpact brute_self(const Topology& t, const Positions& x0, const Positions& x1,
                          const CcdOptions& o) {
  const auto all = [](int, int) { return true; };
  return brute_self(t, x0, x1, o, all, all);
}

CcdOptions kernel_options(double thickness, double tol) {
  CcdOptions o;
  o.thickness = thickness;
  o.toi_tolerance = tol;
  return o;
}

// At zero thickness: no VF or EE pair touches, exactly, before `toi`.
void expect_no_contact_before(const Topology& t, const Positions& x0, const Positions& x1,
                              double toi) {
  if (toi <= 0) return;
  const double before = std::nextafter(toi, 0.0);
  for (int v = 0; v < t.num_vertices(); ++v) {
    for (int f = 0; f < t.num_faces(); ++f) {
      const Face& face = t.faces()[f];
      if (shares(face, v)) continue;
      ASSERT_FALSE(test::exact_vertex_face_contact(vf_query(x0, x1, v, x0, x1, face), before))
          << "vertex " << v << " touches face " << f << " before " << toi;
    }
  }
  const auto& edges = t.edges();
  for (int i = 0; i < t.num_edges(); ++i) {
    for (int j = i + 1; j < t.num_edges(); ++j) {
      const Edge &p = edges[i], &q = edges[j];
      if (p[0] == q[0] || p[0] == q[1] || p[1] == q[0] || p[1] == q[1]) continue;
      ASSERT_FALSE(test::exact_edge_edge_contact(ee_query(x0, x1, p, x0, x1, q), before))
          << "edges " << i << " and " << j << " touch before " << toi;
    }
  }
}

// The query's answer against the brute-force reference `ref` (the kernels at the same
// tolerance over the whole step): a hit exactly where the reference has one, never earlier than
// it by more than the tolerance. (It may be later: a window's kernels see a smaller query, whose
// certified distance is tighter.)
void expect_matches(const EarliestImpact& e, const EarliestImpact& ref, double tol,
                    const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(e.kind == Kind::None, ref.kind == Kind::None) << "toi " << e.toi << " vs " << ref.toi;
  if (ref.kind == Kind::None) {
    EXPECT_EQ(e.toi, 1.0);
    EXPECT_EQ(e.ids, (std::array<int, 2>{-1, -1}));
    return;
  }
  EXPECT_GE(e.toi, ref.toi - tol * (1 + 1e-9));
  EXPECT_LE(e.toi, 1.0);
  EXPECT_GE(e.toi, 0.0);
}

TEST(EarliestImpact, RandomScenesMatchBruteForceAndTheExactOracle) {
  const double tol = 1e-6;
  int hits = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const RandomScene s = test::random_scene(seed);
    for (const double h : {0.0, 1e-3 * s.scale}) {
      DetectOptions o;
      o.thickness = h;
      SelfDetector det(s.faces, s.nv(), s.v0, o);
      const EarliestImpact ref = brute_self(det.topology(), s.v0, s.v1, kernel_options(h, tol));
      const std::string what =
          "seed " + std::to_string(seed) + " h " + std::to_string(h) + ", " + s.describe();
      for (const double window : {0.0, 1.0, 0x1p-4, 0x1p-20}) {
        EarliestOptions eo;
        eo.first_window = window;
        const EarliestImpact e = det.earliest_impact(s.v0, s.v1, eo);
        expect_matches(e, ref, tol, what + " window " + std::to_string(window));
        // The exact oracle (slow) on the automatic window's answer.
        if (h == 0 && window == 0 && seed <= 4) {
          expect_no_contact_before(det.topology(), s.v0, s.v1, e.toi);
        }
        expect_windows(e, what + " window " + std::to_string(window));
      }
      hits += ref.kind != Kind::None;
    }
  }
  EXPECT_GT(hits, 12);  // the scenes do collide
}

TEST(EarliestImpact, SameAnswerForEveryThreadCount) {
  for (std::uint64_t seed = 41; seed <= 50; ++seed) {
    const RandomScene s = test::random_scene(seed, 2);
    SelfDetector det(s.faces, s.nv(), s.v0);
    std::optional<EarliestImpact> first;
    for (const int threads : {1, 2, 4}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      const EarliestImpact e = det.earliest_impact(s.v0, s.v1);
      if (!first) {
        first = e;
        continue;
      }
      EXPECT_EQ(e.toi, first->toi) << "seed " << seed << " threads " << threads;
      EXPECT_EQ(e.kind, first->kind);
      EXPECT_EQ(e.ids, first->ids);
    }
  }
}

// Two square sheets of n x n cells, the upper one `gap` above the lower one at t0 and both
// moving: with gap < h, hundreds of VF and EE pairs are within h from the start.
struct Sheets {
  std::vector<Face> faces;
  Positions x0, x1;
  Sheets(int n, double gap) {
    const int per = (n + 1) * (n + 1);
    x0.resize(2 * per, 3);
    for (int s = 0; s < 2; ++s) {
      for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j) {
          // The upper sheet shifted by a third of a cell, so that its vertices sit over faces.
          const double shift = s == 0 ? 0.0 : 1.0 / 3;
          x0.row(s * per + i * (n + 1) + j) << (i + shift) / n, (j + shift) / n, s * gap;
        }
      }
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          const int a = s * per + i * (n + 1) + j, b = a + 1, c = a + n + 1, d = c + 1;
          faces.push_back({a, b, d});
          faces.push_back({a, d, c});
        }
      }
    }
    x1 = x0;
    for (int v = 0; v < 2 * per; ++v)
      x1(v, 2) += v < per ? 0.1 : -0.3;
  }
};

// Many pairs within the thickness at t0: the answer is time 0 and, of those pairs, the one of
// smallest (kind, ids), as brute force has it, on every thread count.
TEST(EarliestImpact, ManyContactsAtTheStartGiveTheSmallestPair) {
  const double h = 0x1p-6;
  const Sheets s(12, h / 2);
  DetectOptions o;
  o.thickness = h;
  SelfDetector det(s.faces, static_cast<int>(s.x0.rows()), s.x0, o);
  const EarliestImpact ref = brute_self(det.topology(), s.x0, s.x1, kernel_options(h, 1e-6));
  ASSERT_EQ(ref.toi, 0.0);
  for (const int threads : {1, 2, 4}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    const EarliestImpact e = det.earliest_impact(s.x0, s.x1);
    EXPECT_EQ(e.toi, 0.0) << threads << " threads";
    EXPECT_EQ(e.kind, ref.kind) << threads << " threads";
    EXPECT_EQ(e.ids, ref.ids) << threads << " threads";
    EXPECT_EQ(e.windows, 1);
  }
}

// A vertex falling at speed `speed` from height d0 onto a static triangle at z = 0 (and nothing
// else near): contact at distance h at t* = (d0 - h) / speed.
struct Drop {
  std::vector<Face> faces{{0, 1, 2}, {3, 4, 5}};
  Positions x0, x1;
  Drop(double d0, double speed) {
    x0.resize(6, 3);
    x0 << 0, 0, 0, 1, 0, 0, 0, 1, 0,                             // the floor triangle
        0.25, 0.25, d0, 0.75, 0.25, d0 + 1, 0.25, 0.75, d0 + 1;  // a tilted falling one
    x1 = x0;
    for (int v = 3; v < 6; ++v)
      x1(v, 2) -= speed;
  }
};

TEST(EarliestImpact, KnownContactTimes) {
  const double tol = 1e-6;
  // Dyadic distances and speed: the drop ending at t = 1 ends exactly at distance h.
  for (const double h : {0.0, 0x1p-10, 0x1p-4}) {
    DetectOptions o;
    o.thickness = h;
    for (const double t_star : {0.0, 1e-5, 0.3, 0.999, 1.0}) {
      // Vertex 3 is the lowest point of the falling triangle: it reaches distance h at t_star.
      const double speed = 0.5;
      const Drop d(h + t_star * speed, speed);
      SelfDetector det(d.faces, 6, d.x0, o);
      const EarliestImpact e = det.earliest_impact(d.x0, d.x1);
      SCOPED_TRACE("h " + std::to_string(h) + " t* " + std::to_string(t_star));
      ASSERT_EQ(e.kind, Kind::VertexFace);
      EXPECT_EQ(e.ids, (std::array<int, 2>{3, 0}));
      EXPECT_LE(e.toi, t_star);
      // Early by at most the tolerance plus the kernels' certified distance (sqrt(3) 1e-6 L, L
      // about 2 here) at this speed.
      EXPECT_GE(e.toi, t_star - tol - std::sqrt(3.0) * 2e-6 / speed);
    }
    // Stopping short of the floor: nothing comes within h.
    const double speed = 0.5;
    const Drop d(h + speed + 1e-3, speed);
    SelfDetector det(d.faces, 6, d.x0, o);
    const EarliestImpact e = det.earliest_impact(d.x0, d.x1);
    EXPECT_EQ(e.kind, Kind::None);
    EXPECT_EQ(e.toi, 1.0);
  }
}

TEST(EarliestImpact, LinkedPairsAndRestrictionsAsDetectHasThem) {
  const double tol = 1e-6;
  for (std::uint64_t seed = 51; seed <= 62; ++seed) {
    const RandomScene s = test::random_scene(seed);
    DetectOptions o;
    SelfDetector probe(s.faces, s.nv(), s.v0, o);
    const EarliestImpact free = probe.earliest_impact(s.v0, s.v1);
    if (free.kind == Kind::None) continue;
    // Link a vertex of the earliest pair to a vertex of the other feature: that pair drops out.
    const Topology& t = probe.topology();
    const int u = free.kind == Kind::VertexFace ? free.ids[0] : t.edges()[free.ids[0]][0];
    const int w =
        free.kind == Kind::VertexFace ? t.faces()[free.ids[1]][0] : t.edges()[free.ids[1]][0];
    o.linked_vertices = {{u, w}};
    SelfDetector det(s.faces, s.nv(), s.v0, o);
    const auto linked = [&](int a, int b) { return (a == u && b == w) || (a == w && b == u); };
    const auto keep_vf = [&](int v, int f) {
      for (int x : t.faces()[f]) {
        if (linked(v, x)) return false;
      }
      return true;
    };
    const auto keep_ee = [&](int i, int j) {
      for (int x : t.edges()[i]) {
        for (int y : t.edges()[j]) {
          if (linked(x, y)) return false;
        }
      }
      return true;
    };
    const EarliestImpact ref = brute_self(t, s.v0, s.v1, kernel_options(0, tol), keep_vf, keep_ee);
    const EarliestImpact e = det.earliest_impact(s.v0, s.v1);
    expect_matches(e, ref, tol, "links, seed " + std::to_string(seed));
    EXPECT_FALSE(e.kind == free.kind && e.ids == free.ids);

    // Active vertices: pairs with an active vertex only (every third vertex).
    std::vector<int> active;
    std::vector<std::uint8_t> is_active(s.nv(), 0);
    for (int v = seed % 3; v < s.nv(); v += 3) {
      active.push_back(v);
      is_active[v] = 1;
    }
    SelfDetector restricted(s.faces, s.nv(), s.v0);
    restricted.set_active_vertices(active);
    const auto any_vf = [&](int v, int f) {
      const Face& x = t.faces()[f];
      return is_active[v] || is_active[x[0]] || is_active[x[1]] || is_active[x[2]];
    };
    const auto any_ee = [&](int i, int j) {
      const Edge &p = t.edges()[i], &q = t.edges()[j];
      return is_active[p[0]] || is_active[p[1]] || is_active[q[0]] || is_active[q[1]];
    };
    const EarliestImpact ref_r = brute_self(t, s.v0, s.v1, kernel_options(0, tol), any_vf, any_ee);
    expect_matches(restricted.earliest_impact(s.v0, s.v1), ref_r, tol,
                   "active vertices, seed " + std::to_string(seed));
  }
}

TEST(EarliestImpact, TwoMeshesMatchBruteForce) {
  const double tol = 1e-6;
  for (std::uint64_t seed = 63; seed <= 67; ++seed) {
    const RandomScene a = test::random_scene(seed, 1, false);
    RandomScene b = test::random_scene(seed + 1000, 1, false);
    // B in A's coordinates, so that the two meshes meet.
    b.v0 = (b.v0 / b.scale) * a.scale;
    b.v1 = (b.v1 / b.scale) * a.scale;
    for (const double h : {0.0, 1e-3 * a.scale}) {
      DetectOptions o;
      o.thickness = h;
      PairDetector det(a.faces, a.nv(), a.v0, b.faces, b.nv(), b.v0, o);
      const Topology& ta = det.topology_a();
      const Topology& tb = det.topology_b();
      const CcdOptions k = kernel_options(h, tol);
      Brute ref;
      for (int v = 0; v < ta.num_vertices(); ++v) {
        for (int f = 0; f < tb.num_faces(); ++f) {
          const CcdResult r =
              vertex_face_ccd(vf_query(a.v0, a.v1, v, b.v0, b.v1, tb.faces()[f]), k);
          if (r.hit) ref.offer(r.toi, Kind::VertexFace, v, f, false);
        }
      }
      for (int u = 0; u < tb.num_vertices(); ++u) {
        for (int f = 0; f < ta.num_faces(); ++f) {
          const CcdResult r =
              vertex_face_ccd(vf_query(b.v0, b.v1, u, a.v0, a.v1, ta.faces()[f]), k);
          if (r.hit) ref.offer(r.toi, Kind::VertexFace, u, f, true);
        }
      }
      for (int i = 0; i < ta.num_edges(); ++i) {
        for (int j = 0; j < tb.num_edges(); ++j) {
          const CcdResult r =
              edge_edge_ccd(ee_query(a.v0, a.v1, ta.edges()[i], b.v0, b.v1, tb.edges()[j]), k);
          if (r.hit) ref.offer(r.toi, Kind::EdgeEdge, i, j, false);
        }
      }
      const EarliestImpact e = det.earliest_impact(a.v0, a.v1, b.v0, b.v1);
      expect_matches(e, ref.best, tol, "seed " + std::to_string(seed));
    }
  }
}

TEST(EarliestImpact, RefusesBadSettings) {
  const Drop d(0.5, 0.1);
  SelfDetector det(d.faces, 6, d.x0);
  EarliestOptions eo;
  eo.toi_tolerance = 0;
  EXPECT_THROW((void)det.earliest_impact(d.x0, d.x1, eo), InputError);
  eo = {};
  eo.first_window = 0.3;
  EXPECT_THROW((void)det.earliest_impact(d.x0, d.x1, eo), InputError);
  eo.first_window = 2;
  EXPECT_THROW((void)det.earliest_impact(d.x0, d.x1, eo), InputError);
  const Positions short_x = d.x1.topRows(5);
  EXPECT_THROW((void)det.earliest_impact(d.x0, short_x), InputError);
  Positions bad = d.x1;
  bad(2, 1) = std::nan("");
  EXPECT_THROW((void)det.earliest_impact(d.x0, bad), InputError);
}

TEST(EarliestImpact, LeavesDetectionsAsTheyWere) {
  // A query between two detections with kept pairs and fronts changes neither's results.
  const RandomScene s = test::random_scene(7, 2);
  DetectOptions o;
  o.reuse_distance = 1e-2 * s.scale;
  o.reuse_front = true;
  SelfDetector det(s.faces, s.nv(), s.v0, o), fresh(s.faces, s.nv(), s.v0, o);
  const DetectResult before = det.detect(s.v0, s.v1);
  (void)fresh.detect(s.v0, s.v1);
  (void)det.earliest_impact(s.v1, s.v0);
  EXPECT_EQ(det.options(), o);
  const ProximityResult p = det.proximity(s.v1, 5e-3 * s.scale);
  const ProximityResult q = fresh.proximity(s.v1, 5e-3 * s.scale);
  EXPECT_EQ(p.vf, q.vf);
  EXPECT_EQ(p.ee, q.ee);
  const DetectResult again = det.detect(s.v0, s.v1);
  EXPECT_EQ(again.vf, before.vf);
  EXPECT_EQ(again.ee, before.ee);
}

}  // namespace earliest_test
}  // namespace clothcd
