// The cloth-body feature pairs against brute force over every feature pair, with static and
// swept boxes, use flags and a restriction to flagged cloth nodes; and the same lists for 1 and
// 2 threads.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <random>
#include <vector>

#include "clothcd/bvh/bvh.hpp"
#include "grid.hpp"
#include "sim/body_pairs.hpp"

namespace clothcd::sim {
namespace {

using detail::BodyPairs;
using detail::BoxList;
using detail::PairSide;

// One mesh with its topology, BVH and feature boxes over x0 -> x1.
struct Mesh {
  Topology topo;
  std::vector<Vec3> x0, x1;
  Bvh bvh;
  detail::MeshBoxes boxes;
  std::vector<int> vface, eface;

  Mesh(const ClothMeshInput& in, std::mt19937_64& rng, double jitter, const Vec3& motion)
      : topo(in.faces, static_cast<int>(in.positions.size())) {
    for (const Vec3& p : in.positions) {
      x0.push_back(p + test::random_vec(rng, jitter));
      x1.push_back(x0.back() + motion + test::random_vec(rng, jitter));
    }
    bvh = Bvh(topo, x0, BvhBuild::Spatial);
    detail::designated_faces(topo, vface, eface);
  }

  void prepare(double gap, bool swept) {
    RefitOptions ro;
    ro.cones = false;
    ro.thickness = gap;
    if (swept) {
      bvh.refit(x0, x1, ro);
    } else {
      bvh.refit(x0, ro);
    }
    detail::fill_feature_boxes(topo, x0, swept ? x1 : x0, {}, {}, {}, boxes);
  }

  [[nodiscard]] PairSide side(std::span<const std::uint8_t> vuse = {},
                              std::span<const std::uint8_t> euse = {},
                              std::span<const std::uint8_t> fuse = {}) const {
    return {&topo, &bvh, &boxes, vface, eface, vuse, euse, fuse};
  }
};

bool near(const BoxList& a, int i, const BoxList& b, int j, double gap) {
  return (a.lo[i].array() <= b.hi[j].array() + gap).all() &&
         (b.lo[j].array() <= a.hi[i].array() + gap).all();
}

bool used(std::span<const std::uint8_t> flags, int i) {
  return flags.empty() || flags[i] != 0;
}

BodyPairs brute_force(const Mesh& c, const Mesh& b, double gap, std::span<const std::uint8_t> vuse,
                      std::span<const std::uint8_t> euse, std::span<const std::uint8_t> fuse) {
  BodyPairs out;
  for (int i = 0; i < c.topo.num_vertices(); ++i) {
    for (int g = 0; g < b.topo.num_faces(); ++g) {
      if (used(vuse, i) && near(c.boxes.vertex, i, b.boxes.face, g, gap))
        out.vf_cb.emplace_back(i, g);
    }
  }
  for (int u = 0; u < b.topo.num_vertices(); ++u) {
    for (int f = 0; f < c.topo.num_faces(); ++f) {
      if (used(fuse, f) && near(b.boxes.vertex, u, c.boxes.face, f, gap))
        out.vf_bc.emplace_back(u, f);
    }
  }
  for (int a = 0; a < c.topo.num_edges(); ++a) {
    for (int e = 0; e < b.topo.num_edges(); ++e) {
      if (used(euse, a) && near(c.boxes.edge, a, b.boxes.edge, e, gap)) out.ee.emplace_back(a, e);
    }
  }
  return out;  // loops in order: already sorted
}

void expect_same(const BodyPairs& got, const BodyPairs& want) {
  EXPECT_EQ(got.vf_cb, want.vf_cb);
  EXPECT_EQ(got.vf_bc, want.vf_bc);
  EXPECT_EQ(got.ee, want.ee);
}

// A cloth 2 mm over a crumpled "body" grid of another resolution, both jittered.
struct Scene {
  std::mt19937_64 rng{11};
  Mesh cloth{test::grid_cloth(14, 12, 0.3, 0.25, 0.002), rng, 1.5e-3, Vec3(0, -0.003, 0.001)};
  Mesh body{test::grid_cloth(9, 11, 0.32, 0.27, 0.0), rng, 2e-3, Vec3(0.001, 0.001, 0)};
};

TEST(BodyPairs, StaticAndSweptBoxesMatchBruteForce) {
  Scene s;
  for (const bool swept : {false, true}) {
    for (const double gap : {1e-5, 1e-3, 4e-3}) {
      s.cloth.prepare(gap, swept);
      s.body.prepare(gap, swept);
      const BodyPairs got = detail::close_feature_pairs(s.cloth.side(), s.body.side(), gap);
      const BodyPairs want = brute_force(s.cloth, s.body, gap, {}, {}, {});
      expect_same(got, want);
      // Not vacuous: every kind of pair occurs.
      EXPECT_FALSE(want.vf_cb.empty());
      EXPECT_FALSE(want.vf_bc.empty());
      EXPECT_FALSE(want.ee.empty());
    }
  }
}

TEST(BodyPairs, SkippedFacePairsLeaveOutExactlyTheirFeaturePairs) {
  // Every third (cloth face, body face) pair skipped: the pairs whose designated faces are a
  // skipped pair go, and only those.
  Scene s;
  const double gap = 1e-3;
  s.cloth.prepare(gap, false);
  s.body.prepare(gap, false);
  auto skip = [](int f, int g) { return (f + 2 * g) % 3 == 0; };
  const BodyPairs got = detail::close_feature_pairs(s.cloth.side(), s.body.side(), gap, {}, skip);
  BodyPairs want = brute_force(s.cloth, s.body, gap, {}, {}, {});
  const std::size_t all = want.vf_cb.size() + want.vf_bc.size() + want.ee.size();
  std::erase_if(want.vf_cb, [&](auto p) { return skip(s.cloth.vface[p.first], p.second); });
  std::erase_if(want.vf_bc, [&](auto p) { return skip(p.second, s.body.vface[p.first]); });
  std::erase_if(want.ee,
                [&](auto p) { return skip(s.cloth.eface[p.first], s.body.eface[p.second]); });
  expect_same(got, want);
  const std::size_t kept = want.vf_cb.size() + want.vf_bc.size() + want.ee.size();
  EXPECT_GT(kept, 0u);
  EXPECT_LT(kept, all);
}

TEST(BodyPairs, UseFlagsAndNodeRestrictionMatchBruteForce) {
  Scene s;
  const double gap = 1e-3;
  s.cloth.prepare(gap, true);
  s.body.prepare(gap, true);
  const Topology& t = s.cloth.topo;
  // Active vertices as in a restricted CCD pass, one vertex left out as if escaping.
  std::vector<std::uint8_t> active(t.num_vertices(), 0);
  for (int i = 0; i < t.num_vertices(); i += 7)
    active[i] = 1;
  const int escaping = 14;
  std::vector<std::uint8_t> vuse(active), euse = t.edges_touching(active);
  vuse[escaping] = 0;
  for (int e = 0; e < t.num_edges(); ++e) {
    if (t.edges()[e][0] == escaping || t.edges()[e][1] == escaping) euse[e] = 0;
  }
  std::vector<std::uint8_t> fuse(t.num_faces(), 1);
  for (int f = 0; f < t.num_faces(); ++f) {
    const Face& q = t.faces()[f];
    if (q[0] == escaping || q[1] == escaping || q[2] == escaping) fuse[f] = 0;
  }
  const std::vector<std::uint8_t> faces = t.faces_touching(active);
  const std::vector<std::uint8_t> nodes = s.cloth.bvh.nodes_holding(faces);
  const BodyPairs got =
      detail::close_feature_pairs(s.cloth.side(vuse, euse, fuse), s.body.side(), gap, nodes);
  // The restriction leaves the body's vertices only the faces below flagged nodes.
  std::vector<std::uint8_t> fuse_visited(fuse);
  for (int f = 0; f < t.num_faces(); ++f)
    fuse_visited[f] = fuse[f] && faces[f];
  const BodyPairs want = brute_force(s.cloth, s.body, gap, vuse, euse, fuse_visited);
  expect_same(got, want);
  EXPECT_FALSE(want.vf_cb.empty());
  EXPECT_FALSE(want.ee.empty());
}

TEST(BodyPairs, FeatureBoxesAreTheBoxesOfBothPositionsWhereUsed) {
  Scene s;
  const Mesh& m = s.cloth;
  const Topology& t = m.topo;
  detail::MeshBoxes boxes;
  detail::fill_feature_boxes(t, m.x0, m.x1, {}, {}, {}, boxes);
  auto expect_box = [&](const detail::BoxList& b, int k, std::initializer_list<int> ids) {
    Vec3 lo = Vec3::Constant(INFINITY), hi = -lo;
    for (int i : ids) {
      lo = lo.cwiseMin(m.x0[i]).cwiseMin(m.x1[i]);
      hi = hi.cwiseMax(m.x0[i]).cwiseMax(m.x1[i]);
    }
    EXPECT_EQ(b.lo[k], lo) << k;
    EXPECT_EQ(b.hi[k], hi) << k;
  };
  for (int v = 0; v < t.num_vertices(); ++v)
    expect_box(boxes.vertex, v, {v});
  for (int e = 0; e < t.num_edges(); ++e)
    expect_box(boxes.edge, e, {t.edges()[e][0], t.edges()[e][1]});
  for (int f = 0; f < t.num_faces(); ++f)
    expect_box(boxes.face, f, {t.faces()[f][0], t.faces()[f][1], t.faces()[f][2]});
  // With use flags only the used features change: the rest keep the static boxes of x0.
  detail::MeshBoxes kept;
  detail::fill_feature_boxes(t, m.x0, m.x0, {}, {}, {}, kept);
  std::vector<std::uint8_t> vuse(t.num_vertices(), 0), euse(t.num_edges(), 0);
  std::vector<std::uint8_t> fuse(t.num_faces(), 0);
  vuse[3] = euse[5] = fuse[7] = 1;
  const detail::MeshBoxes before = kept;
  detail::fill_feature_boxes(t, m.x0, m.x1, vuse, euse, fuse, kept);
  for (int v = 0; v < t.num_vertices(); ++v)
    EXPECT_EQ(kept.vertex.lo[v], (v == 3 ? boxes : before).vertex.lo[v]) << v;
  for (int e = 0; e < t.num_edges(); ++e)
    EXPECT_EQ(kept.edge.hi[e], (e == 5 ? boxes : before).edge.hi[e]) << e;
  for (int f = 0; f < t.num_faces(); ++f)
    EXPECT_EQ(kept.face.lo[f], (f == 7 ? boxes : before).face.lo[f]) << f;
}

TEST(BodyPairs, SameListsForOneAndTwoThreads) {
  Scene s;
  const double gap = 1e-3;
  s.cloth.prepare(gap, false);
  s.body.prepare(gap, false);
  BodyPairs one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = detail::close_feature_pairs(s.cloth.side(), s.body.side(), gap);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = detail::close_feature_pairs(s.cloth.side(), s.body.side(), gap);
  }
  expect_same(one, two);
}

}  // namespace
}  // namespace clothcd::sim
