// DetectOptions::reuse_distance: a proximity query after a detect() that kept its triangle pairs
// equals the all-pairs distance oracle, whether no vertex moved since, a few did (the kept pairs
// plus a restricted traversal), most did or the query reaches farther (a full traversal); the
// widened boxes change no CCD result; and what turns the reuse off does so.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "api_scenes.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd {
// A namespace of its own: the research types below stay in this file of the unity build.
namespace reuse_test {

// The research detector and options (unsound rules, optimal cones, verification).
using research::DetectOptions;
using research::SelfDetector;

using namespace clothcd::test;

constexpr double kKept = 0.05;  // the reuse distance of these tests

// `v` with about `share` of its vertices (a seeded random choice) moved by up to `by` per axis.
Positions moved(const Positions& v, double share, double by, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0), d(-by, by);
  Positions out = v;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    if (u(rng) >= share) continue;
    for (int k = 0; k < 3; ++k)
      out(i, k) += d(rng);
  }
  return out;
}

void expect_same(const ProximityResult& r, const ProximityResult& ref) {
  EXPECT_EQ(vf_pairs(r.vf), vf_pairs(ref.vf));
  EXPECT_EQ(ee_pairs(r.ee), ee_pairs(ref.ee));
  for (std::size_t i = 0; i < std::min(r.vf.size(), ref.vf.size()); ++i)
    EXPECT_EQ(r.vf[i].distance, ref.vf[i].distance);
  for (std::size_t i = 0; i < std::min(r.ee.size(), ref.ee.size()); ++i)
    EXPECT_EQ(r.ee[i].distance, ref.ee[i].distance);
}

std::vector<research::ProceduralScene> reuse_scenes() {
  return {research::crumpled_sheet(8, 2), research::twisted_strip(30, 3),
          research::stacked_sheets(6)};
}

TEST(ProximityReuse, EqualsAllPairsDistance) {
  struct Case {
    const char* name;
    double share;  // of the vertices moved after the detect
    double h;
    bool reused;
  };
  const Case cases[] = {
      {"none moved", 0.0, kKept, true},  {"none moved, nearer", 0.0, 0.01, true},
      {"a few moved", 0.1, 0.01, true},  {"a few moved, at the kept distance", 0.1, kKept, true},
      {"most moved", 0.6, kKept, false}, {"farther than kept", 0.0, 1.2 * kKept, false}};
  for (const auto& s : reuse_scenes()) {
    const Topology topo(s.faces, s.num_vertices);
    const Positions end = 0.5 * (s.v_t0 + s.v_t1);  // folded: features come close
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      DetectOptions plain;
      plain.build = build;
      DetectOptions o = plain;
      o.reuse_distance = kKept;
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      SelfDetector ref_det(s.faces, s.num_vertices, s.v_t0, plain);
      // The widened boxes find the same collisions, on the whole step and on its first half.
      for (const Positions* to : {&s.v_t1, &end}) {
        const DetectResult a = det.detect(s.v_t0, *to);
        const DetectResult b = ref_det.detect(s.v_t0, *to);
        EXPECT_EQ(a.vf, b.vf) << s.name;
        EXPECT_EQ(a.ee, b.ee) << s.name;
        if (to == &s.v_t1) {
          EXPECT_GT(a.vf.size() + a.ee.size(), 0u) << s.name;
        }
      }
      std::uint32_t seed = 1;
      for (const Case& c : cases) {
        SCOPED_TRACE(::testing::Message() << s.name << " build " << int(build) << ": " << c.name);
        static_cast<void>(det.detect(s.v_t0, end));
        const Positions v = moved(end, c.share, 0.02, seed++);
        const ProximityResult r = det.proximity(v, c.h);
        const ProximityResult ref = brute_force_proximity(topo, v, c.h);
        EXPECT_GT(ref.vf.size() + ref.ee.size(), 0u);
        expect_same(r, ref);
        EXPECT_EQ(r.reused_pairs > 0, c.reused) << r.reused_pairs;
      }
    }
  }
}

// A simulator's passes: an unrestricted detect keeps its pairs, restricted ones after it (the
// active vertices moved again) keep them too, and the next proximity query reuses them. Also
// with the simulator's options: a CCD thickness, and Sound culling (no cone culls with it).
TEST(ProximityReuse, KeptAcrossRestrictedPasses) {
  DetectOptions thick;
  thick.culling = Culling::Sound;
  thick.thickness = 1e-3;
  for (const auto& s : reuse_scenes()) {
    for (DetectOptions o : {DetectOptions{}, thick}) {
      SCOPED_TRACE(::testing::Message() << s.name << " thickness " << o.thickness);
      const Topology topo(s.faces, s.num_vertices);
      const Positions end = 0.5 * (s.v_t0 + s.v_t1);
      o.reuse_distance = kKept;
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      static_cast<void>(det.detect(s.v_t0, end));
      std::vector<int> active;
      Positions later = end;
      for (int v = 0; v < s.num_vertices; v += 9) {
        active.push_back(v);
        later.row(v) += Eigen::RowVector3d(0.01, -0.015, 0.02);
      }
      det.set_active_vertices(active);
      static_cast<void>(det.detect(s.v_t0, later));
      det.clear_active();
      const ProximityResult r = det.proximity(later, kKept);
      EXPECT_GT(r.reused_pairs, 0u);
      expect_same(r, brute_force_proximity(topo, later, kKept));
      // The same answer on 1 and 3 threads.
      for (int threads : {1, 3}) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        static_cast<void>(det.detect(s.v_t0, end));
        const ProximityResult t = det.proximity(later, kKept);
        EXPECT_GT(t.reused_pairs, 0u);
        expect_same(t, r);
      }
    }
  }
}

// A CCD thickness at or above the reuse distance already gives boxes wide enough: the pairs are
// kept all the same, and the collisions are those of a detector without reuse.
TEST(ProximityReuse, KeptWhenTheThicknessAlreadyReachesTheDistance) {
  const research::ProceduralScene s = research::crumpled_sheet(8, 2);
  const Topology topo(s.faces, s.num_vertices);
  const Positions end = 0.5 * (s.v_t0 + s.v_t1);
  for (double reach : {kKept, 0.5 * kKept}) {
    SCOPED_TRACE(::testing::Message() << "reuse distance " << reach);
    DetectOptions plain;
    plain.culling = Culling::Sound;
    plain.thickness = kKept;
    DetectOptions o = plain;
    o.reuse_distance = reach;
    SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
    SelfDetector ref_det(s.faces, s.num_vertices, s.v_t0, plain);
    const DetectResult a = det.detect(s.v_t0, end);
    const DetectResult b = ref_det.detect(s.v_t0, end);
    EXPECT_EQ(a.vf, b.vf);
    EXPECT_EQ(a.ee, b.ee);
    const Positions v = moved(end, 0.1, 0.02, 7);
    const ProximityResult r = det.proximity(v, reach);
    EXPECT_GT(r.reused_pairs, 0u);
    expect_same(r, brute_force_proximity(topo, v, reach));
  }
}

TEST(ProximityReuse, OffWhereItCannotHold) {
  const research::ProceduralScene s = research::crumpled_sheet(8, 2);
  const Topology topo(s.faces, s.num_vertices);
  const Positions end = 0.5 * (s.v_t0 + s.v_t1);
  const ProximityResult ref = brute_force_proximity(topo, end, kKept);
  DetectOptions o;
  o.reuse_distance = kKept;
  {
    SCOPED_TRACE("no detect yet");
    SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
    const ProximityResult r = det.proximity(end, kKept);
    EXPECT_EQ(r.reused_pairs, 0u);
    expect_same(r, ref);
  }
  {
    SCOPED_TRACE("options set again");
    SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
    static_cast<void>(det.detect(s.v_t0, end));
    det.set_options(o);
    const ProximityResult r = det.proximity(end, kKept);
    EXPECT_EQ(r.reused_pairs, 0u);
    expect_same(r, ref);
  }
  {
    SCOPED_TRACE("the unsound rules may cull close pairs: refused with a reuse distance");
    for (auto rule : {research::CullingRule::Cone, research::CullingRule::Gated}) {
      DetectOptions cone = o;
      cone.research.culling = rule;
      EXPECT_THROW(SelfDetector(s.faces, s.num_vertices, s.v_t0, cone), InputError);
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      EXPECT_THROW(det.set_options(cone), InputError);
    }
  }
  {
    SCOPED_TRACE("a query under an active restriction keeps its scope");
    DetectOptions plain;
    SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
    SelfDetector ref_det(s.faces, s.num_vertices, s.v_t0, plain);
    static_cast<void>(det.detect(s.v_t0, end));
    const std::vector<int> active{0, 5, 17, 40};
    det.set_active_vertices(active);
    ref_det.set_active_vertices(active);
    const ProximityResult r = det.proximity(end, kKept);
    const ProximityResult r_ref = ref_det.proximity(end, kKept);
    EXPECT_EQ(r.reused_pairs, 0u);
    expect_same(r, r_ref);
    EXPECT_LT(r.vf.size() + r.ee.size(), ref.vf.size() + ref.ee.size());
  }
}

// Sound culling certifies its culled nodes free of feature pairs within the reuse distance, so
// the pairs it keeps still serve the proximity query: cones and reuse work together.
TEST(ProximityReuse, SoundCullingKeepsWhatTheQueryNeeds) {
  std::uint64_t culled = 0, reused = 0;
  for (const research::ProceduralScene& s : reuse_scenes()) {
    for (const double reuse : {0.002, kKept}) {
      SCOPED_TRACE(::testing::Message() << s.name << " reuse distance " << reuse);
      const Topology topo(s.faces, s.num_vertices);
      const Positions end = 0.5 * (s.v_t0 + s.v_t1);
      DetectOptions o;
      o.reuse_distance = reuse;
      o.culling = Culling::Sound;
      o.build = BvhBuild::Patch;
      DetectOptions plain = o;
      plain.culling = Culling::None;
      SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
      SelfDetector ref_det(s.faces, s.num_vertices, s.v_t0, plain);
      const DetectResult r = det.detect(s.v_t0, end);
      const DetectResult r_ref = ref_det.detect(s.v_t0, end);
      EXPECT_EQ(r.vf, r_ref.vf);
      EXPECT_EQ(r.ee, r_ref.ee);
      culled += r.stats.nodes_culled;
      for (const double share : {0.0, 0.1}) {
        const Positions at = moved(end, share, 0.01, 7);
        const ProximityResult p = det.proximity(at, reuse);
        reused += p.reused_pairs;
        expect_same(p, brute_force_proximity(topo, at, reuse));
        static_cast<void>(det.detect(s.v_t0, end));  // keep the pairs again for the next query
      }
    }
  }
  // The cones did cull and the queries did take kept pairs, or the test shows nothing.
  EXPECT_GT(culled, 0u);
  EXPECT_GT(reused, 0u);
}

// Linked vertices (DetectOptions::linked_vertices) join no reported pair in proximity(), as in
// detect(): the query equals the all-pairs distance oracle less the linked pairs, with and
// without the reuse of a detection's pairs (none moved, a few moved), and with an active
// restriction on top.
TEST(ProximityLinks, LeavesLinkedPairsOut) {
  std::size_t restricted_found = 0;  // pairs of the restricted queries, over all scenes
  for (const auto& s : reuse_scenes()) {
    SCOPED_TRACE(s.name);
    const Topology topo(s.faces, s.num_vertices);
    const Positions end = 0.5 * (s.v_t0 + s.v_t1);
    // Link a vertex of every other close pair to its partner feature's first vertex, so that the
    // links remove pairs the query would report otherwise (and more pairs on those vertices).
    const ProximityResult all = brute_force_proximity(topo, end, kKept);
    std::vector<std::pair<int, int>> links;
    for (std::size_t i = 0; i < all.vf.size(); i += 2)
      links.emplace_back(topo.faces()[all.vf[i].face][0], all.vf[i].vertex);
    for (std::size_t i = 0; i < all.ee.size(); i += 2)
      links.emplace_back(topo.edges()[all.ee[i].edge_a][1], topo.edges()[all.ee[i].edge_b][0]);
    ASSERT_FALSE(links.empty());
    // The queries' positions: those of the detection, and a few vertices moved since.
    struct At {
      Positions v;
      ProximityResult ref;  // the oracle less the linked pairs
    };
    std::vector<At> ats;
    for (double share : {0.0, 0.1}) {
      At a{moved(end, share, 0.01, 11), {}};
      a.ref = brute_force_proximity(topo, a.v, kKept, links);
      const ProximityResult unlinked = brute_force_proximity(topo, a.v, kKept);
      EXPECT_LT(a.ref.vf.size() + a.ref.ee.size(), unlinked.vf.size() + unlinked.ee.size());
      ats.push_back(std::move(a));
    }
    auto linked = [&](int u, int w) {
      return std::count(links.begin(), links.end(), std::pair(u, w)) +
                 std::count(links.begin(), links.end(), std::pair(w, u)) >
             0;
    };
    for (double reuse : {0.0, kKept}) {
      for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
        SCOPED_TRACE(::testing::Message() << "reuse " << reuse << " build " << int(build));
        DetectOptions o;
        o.build = build;
        o.reuse_distance = reuse;
        o.linked_vertices = links;
        SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
        for (const At& a : ats) {
          const DetectResult d = det.detect(s.v_t0, end);
          const ProximityResult r = det.proximity(a.v, kKept);
          expect_same(r, a.ref);
          EXPECT_EQ(r.reused_pairs > 0, reuse > 0);
          for (const auto& c : d.vf) {  // detect() leaves the same pairs out
            for (int x : c.face_vertices)
              EXPECT_FALSE(linked(x, c.vertex));
          }
        }
        // Under an active restriction: the restricted query's pairs less the linked ones.
        std::vector<int> active;
        for (int v = 0; v < s.num_vertices; v += 3)
          active.push_back(v);
        DetectOptions plain = o;
        plain.linked_vertices.clear();
        SelfDetector unlinked(s.faces, s.num_vertices, s.v_t0, plain);
        det.set_active_vertices(active);
        unlinked.set_active_vertices(active);
        const ProximityResult r = det.proximity(ats[0].v, kKept);
        ProximityResult ref = unlinked.proximity(ats[0].v, kKept);
        std::erase_if(ref.vf, [&](const auto& p) {
          const Face& t = topo.faces()[p.face];
          return linked(p.vertex, t[0]) || linked(p.vertex, t[1]) || linked(p.vertex, t[2]);
        });
        std::erase_if(ref.ee, [&](const auto& p) {
          const Edge &a = topo.edges()[p.edge_a], &b = topo.edges()[p.edge_b];
          return linked(a[0], b[0]) || linked(a[0], b[1]) || linked(a[1], b[0]) ||
                 linked(a[1], b[1]);
        });
        restricted_found += ref.vf.size() + ref.ee.size();
        expect_same(r, ref);
        det.clear_active();
      }
    }
  }
  EXPECT_GT(restricted_found, 0u);
}

// The BVH build is fixed at construction: set_options with another one is refused, the same
// build accepted.
TEST(SetOptions, RefusesAnotherBuild) {
  const research::ProceduralScene s = research::crumpled_sheet(4, 1);
  DetectOptions o;
  o.build = BvhBuild::Patch;
  SelfDetector det(s.faces, s.num_vertices, s.v_t0, o);
  o.culling = Culling::Sound;
  EXPECT_NO_THROW(det.set_options(o));
  o.build = BvhBuild::Spatial;
  EXPECT_THROW(det.set_options(o), InputError);
  EXPECT_EQ(det.options().build, BvhBuild::Patch);
  EXPECT_EQ(det.options().culling, Culling::Sound);
}

TEST(ProximityReuse, RejectsBadDistances) {
  const research::ProceduralScene s = research::crumpled_sheet(4, 1);
  for (double d :
       {-1e-3, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    DetectOptions o;
    o.reuse_distance = d;
    EXPECT_THROW(SelfDetector(s.faces, s.num_vertices, s.v_t0, o), InputError) << d;
    SelfDetector det(s.faces, s.num_vertices, s.v_t0);
    EXPECT_THROW(det.set_options(o), InputError) << d;
  }
}

}  // namespace reuse_test
}  // namespace clothcd
