// BVH structure against brute force: permutation ranges, boxes enclosing their triangles, the
// connectivity flag against a breadth-first search, disks with one consistent boundary loop.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>
#include <set>

#include "bvh/optimal_cones.hpp"
#include "clothcd/bvh/bvh.hpp"
#include "clothcd/research/procedural.hpp"
#include "support/random_gen.hpp"

namespace clothcd {
namespace {

std::vector<Eigen::Vector3d> points(const Positions& p) {
  std::vector<Eigen::Vector3d> v(p.rows());
  for (int i = 0; i < p.rows(); ++i)
    v[i] = p.row(i).transpose();
  return v;
}

bool connected_brute(const Topology& t, const std::vector<int>& faces) {
  std::set<int> in(faces.begin(), faces.end()), seen{faces[0]};
  std::vector<int> q{faces[0]};
  for (std::size_t k = 0; k < q.size(); ++k) {
    for (int e : t.face_edges(q[k])) {
      for (int g : t.edge_faces(e)) {
        if (in.count(g) && seen.insert(g).second) q.push_back(g);
      }
    }
  }
  return q.size() == faces.size();
}

TEST(Bvh, StructureAndFlagsMatchBruteForce) {
  for (const auto& s : {research::stacked_sheets(6), research::winding_strip(40, 2),
                        research::crumpled_sheet(8, 7), research::twisted_strip(30, 3)}) {
    const Topology topo(s.faces, s.num_vertices);
    const auto v0 = points(s.v_t0), v1 = points(s.v_t1);
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      SCOPED_TRACE(::testing::Message() << s.name << " build " << int(build));
      Bvh bvh(topo, v0, build);
      RefitOptions ro;
      ro.policy = ConePolicy::Exact;
      bvh.refit(v0, v1, ro);
      const auto& nodes = bvh.nodes();
      std::vector<int> sorted = bvh.prim_ids();
      std::sort(sorted.begin(), sorted.end());
      std::vector<int> all(topo.num_faces());
      std::iota(all.begin(), all.end(), 0);
      EXPECT_EQ(sorted, all);
      ASSERT_EQ(bvh.prim_faces().size(), all.size());
      for (std::size_t p = 0; p < all.size(); ++p)
        EXPECT_EQ(bvh.prim_faces()[p], topo.faces()[bvh.prim_ids()[p]]) << "position " << p;
      for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
        const BvhNode& n = nodes[i];
        std::vector<int> faces(bvh.prim_ids().begin() + n.first,
                               bvh.prim_ids().begin() + n.first + n.count);
        EXPECT_EQ(n.connected(), connected_brute(topo, faces)) << "node " << i;
        if (n.disk()) {
          EXPECT_TRUE(n.connected());
        }
        for (int f : faces) {
          for (int c : topo.faces()[f]) {
            for (int k = 0; k < 3; ++k) {
              EXPECT_LE(n.lo[k], std::min(v0[c][k], v1[c][k]));
              EXPECT_GE(n.hi[k], std::max(v0[c][k], v1[c][k]));
            }
          }
        }
        if (!n.is_leaf()) {
          EXPECT_GT(n.left, i);  // children after their parent
          EXPECT_EQ(nodes[n.left].first, n.first);
          EXPECT_EQ(nodes[n.left].count + nodes[n.left + 1].count, n.count);
        }
        if (!n.is_leaf() && n.disk()) {
          EXPECT_GE(bvh.contour(i).size(), 3u);
        }
      }
      // The whole of a connected single sheet is a disk in either build.
      if (s.name == "crumpled_sheet") {
        EXPECT_TRUE(nodes[0].disk());
      }
      if (s.name == "stacked_sheets") {
        EXPECT_FALSE(nodes[0].connected());
      }
      if (build == BvhBuild::Patch && topo.num_components() == 1) {
        EXPECT_EQ(bvh.num_connected_internal(), bvh.num_internal());
      }
    }
  }
}

// The connectivity flag on random meshes: boundaries, edges of three or more faces, duplicate
// faces, several components, faces scattered in space so that splits cut them apart.
// nodes_holding against its definition: each node's flag is the OR of the flags of the faces in
// its range, for flags of several bits on none, few, many and all of the faces.
TEST(Bvh, NodesHoldingIsTheOrOfTheFlagsBelow) {
  std::mt19937_64 rng(5);
  for (const auto& s : {research::crumpled_sheet(10, 3), research::twisted_strip(30, 3)}) {
    const Topology topo(s.faces, s.num_vertices);
    const auto v0 = points(s.v_t0);
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      const Bvh bvh(topo, v0, build);
      for (int share : {0, 1, 8, 100}) {
        SCOPED_TRACE(::testing::Message()
                     << s.name << " build " << int(build) << " share " << share);
        std::vector<std::uint8_t> flags(topo.num_faces(), 0);
        for (auto& f : flags) {
          if (static_cast<int>(rng() % 100) < share) f = static_cast<std::uint8_t>(1 + rng() % 7);
        }
        const std::vector<std::uint8_t> held = bvh.nodes_holding(flags);
        ASSERT_EQ(held.size(), bvh.nodes().size());
        for (int i = 0; i < static_cast<int>(held.size()); ++i) {
          const BvhNode& n = bvh.nodes()[i];
          std::uint8_t expected = 0;
          for (int k = n.first; k < n.first + n.count; ++k)
            expected |= flags[bvh.prim_ids()[k]];
          EXPECT_EQ(held[i], expected) << "node " << i;
        }
      }
    }
  }
}

TEST(Bvh, ConnectedFlagMatchesBruteForceOnRandomMeshes) {
  int connected = 0, disconnected = 0;
  for (std::uint64_t seed = 1; seed <= 80; ++seed) {
    test::Gen gen(seed);
    const int nv = gen.integer(6, 40);
    const int nf = gen.integer(2, 70);
    std::vector<Face> faces;
    for (int i = 0; i < nf; ++i) {
      const Face t = gen.face(nv);
      faces.push_back(t);
      if (gen.integer(0, 9) == 0) faces.push_back({t[2], t[0], t[1]});
    }
    const Topology topo(faces, nv);
    std::vector<Eigen::Vector3d> v(nv);
    for (auto& x : v)
      x = gen.vec(1.0);
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      SCOPED_TRACE(::testing::Message() << "seed " << seed << " build " << int(build));
      const Bvh bvh(topo, v, build);
      for (int i = 0; i < static_cast<int>(bvh.nodes().size()); ++i) {
        const BvhNode& n = bvh.nodes()[i];
        const std::vector<int> in(bvh.prim_ids().begin() + n.first,
                                  bvh.prim_ids().begin() + n.first + n.count);
        const bool want = connected_brute(topo, in);
        EXPECT_EQ(n.connected(), want) << "node " << i;
        (want ? connected : disconnected) += n.is_leaf() ? 0 : 1;
      }
    }
  }
  EXPECT_GT(connected, 500);
  EXPECT_GT(disconnected, 500);
}

// refit_changed, and refit_moved with the moved vertices flagged, over a sequence of calls (a few
// vertices moved, a static refit between, other options, a switch from one to the other) give
// after every call, bit for bit, the boxes and cones of a fresh full refit, for every policy.
TEST(Bvh, RefitChangedEqualsFullRefitAfterEveryCall) {
  for (const auto& s : {research::crumpled_sheet(8, 7), research::twisted_strip(30, 3),
                        research::stacked_sheets(6)}) {
    const Topology topo(s.faces, s.num_vertices);
    const auto v0 = points(s.v_t0);
    // The three policies, then the research reference (optimal cones).
    const std::pair<ConePolicy, bool> cones[] = {{ConePolicy::Provot, false},
                                                 {ConePolicy::Proposed, false},
                                                 {ConePolicy::Exact, false},
                                                 {ConePolicy::Proposed, true}};
    for (const auto& [policy, optimal] : cones) {
      SCOPED_TRACE(::testing::Message()
                   << s.name << " policy " << int(policy) << " optimal " << optimal);
      auto v1 = points(s.v_t1);
      Bvh reused(topo, v0, BvhBuild::Spatial);
      Bvh flagged(topo, v0, BvhBuild::Spatial);
      auto last_v1 = v1;
      RefitOptions ro;
      ro.policy = policy;
      ro.thickness = 1e-3;
      // Each refit of the tree, with the optimal cones where asked.
      using detail::OptimalCones;
      const bool opt = optimal;
      auto refit_static = [&](Bvh& b) { opt ? OptimalCones::refit(b, v0, ro) : b.refit(v0, ro); };
      auto refit = [&](Bvh& b) { opt ? OptimalCones::refit(b, v0, v1, ro) : b.refit(v0, v1, ro); };
      auto refit_changed = [&](Bvh& b) {
        opt ? OptimalCones::refit_changed(b, v0, v1, ro) : b.refit_changed(v0, v1, ro);
      };
      auto refit_moved = [&](Bvh& b, std::span<const std::uint8_t> moved) {
        opt ? OptimalCones::refit_moved(b, v0, v1, ro, moved) : b.refit_moved(v0, v1, ro, moved);
      };
      for (int call = 0; call < 6; ++call) {
        if (call == 3) {  // static: the next call starts over
          refit_static(reused);
          refit_static(flagged);
        }
        if (call == 4) ro.thickness = 2e-3;  // other options: likewise
        if (call > 0) {
          for (std::size_t v = call; v < v1.size(); v += 11)
            v1[v] += Eigen::Vector3d(0.02 * call, -0.01, 0.03);
        }
        refit_changed(reused);
        // The vertices whose motion changed since the last call (v0 stays).
        std::vector<std::uint8_t> moved(v1.size(), 0);
        for (std::size_t v = 0; v < v1.size(); ++v)
          moved[v] = v1[v] != last_v1[v] ? 1 : 0;
        last_v1 = v1;
        if (call == 5) {
          refit_changed(flagged);  // after refit_moved: no copies, a full refit
        } else {
          refit_moved(flagged, moved);
        }
        Bvh fresh(topo, v0, BvhBuild::Spatial);
        refit(fresh);
        for (const Bvh* tree : {&reused, &flagged}) {
          for (std::size_t i = 0; i < fresh.nodes().size(); ++i) {
            for (int k = 0; k < 3; ++k) {
              ASSERT_EQ(tree->nodes()[i].lo[k], fresh.nodes()[i].lo[k]) << "call " << call;
              ASSERT_EQ(tree->nodes()[i].hi[k], fresh.nodes()[i].hi[k]) << "call " << call;
            }
            ASSERT_EQ(tree->cones()[i].axis, fresh.cones()[i].axis) << "call " << call;
            ASSERT_EQ(tree->cones()[i].half_angle, fresh.cones()[i].half_angle) << "call " << call;
          }
        }
      }
    }
  }
}

// With cone_min_triangles, the boxes are those of a plain refit, every node of at least that many
// triangles (and every child such a node merges) has a cone holding its triangles' normals over
// the step, and refit_moved() still gives the full refit's boxes and cones bit for bit.
TEST(Bvh, ConeMinTrianglesConesHoldTheirNormalsAndRefitMovedMatches) {
  int total_narrow = 0;  // cones below pi/2 checked
  for (const auto& s : {research::crumpled_sheet(8, 7), research::twisted_strip(30, 3),
                        research::stacked_sheets(6)}) {
    const Topology topo(s.faces, s.num_vertices);
    const auto v0 = points(s.v_t0);
    for (const ConePolicy policy : {ConePolicy::Provot, ConePolicy::Proposed}) {
      for (const int min : {2, 5, 16}) {
        SCOPED_TRACE(::testing::Message() << s.name << " policy " << int(policy) << " min " << min);
        auto v1 = points(s.v_t1);
        RefitOptions ro;
        ro.policy = policy;
        ro.thickness = 1e-3;
        Bvh plain(topo, v0, BvhBuild::Patch);
        plain.refit(v0, v1, ro);
        ro.cone_min_triangles = min;
        Bvh flagged(topo, v0, BvhBuild::Patch);
        auto last_v1 = v1;
        for (int call = 0; call < 4; ++call) {
          if (call > 0) {
            for (std::size_t v = call; v < v1.size(); v += 11)
              v1[v] += Eigen::Vector3d(0.002 * call, -0.001, 0.003);
          }
          std::vector<std::uint8_t> moved(v1.size(), 0);
          for (std::size_t v = 0; v < v1.size(); ++v)
            moved[v] = v1[v] != last_v1[v] ? 1 : 0;
          last_v1 = v1;
          flagged.refit_moved(v0, v1, ro, moved);
          Bvh fresh(topo, v0, BvhBuild::Patch);
          fresh.refit(v0, v1, ro);
          const auto& nodes = fresh.nodes();
          for (std::size_t i = 0; i < nodes.size(); ++i) {
            for (int k = 0; k < 3; ++k) {
              ASSERT_EQ(flagged.nodes()[i].lo[k], nodes[i].lo[k]) << "call " << call;
              ASSERT_EQ(flagged.nodes()[i].hi[k], nodes[i].hi[k]) << "call " << call;
              if (call == 0) {
                ASSERT_EQ(plain.nodes()[i].lo[k], nodes[i].lo[k]);
                ASSERT_EQ(plain.nodes()[i].hi[k], nodes[i].hi[k]);
              }
            }
          }
          int narrow = 0;
          for (std::size_t i = 0; i < nodes.size(); ++i) {
            const BvhNode& n = nodes[i];
            if (n.count < min) continue;
            // The node's cone and, for an internal node, the two it merged.
            std::vector<std::size_t> with_cones{i};
            if (!n.is_leaf()) with_cones = {i, std::size_t(n.left), std::size_t(n.left + 1)};
            for (std::size_t j : with_cones) {
              ASSERT_EQ(flagged.cones()[j].axis, fresh.cones()[j].axis) << "call " << call;
              ASSERT_EQ(flagged.cones()[j].half_angle, fresh.cones()[j].half_angle);
            }
            const NormalCone& cone = fresh.cones()[i];
            if (cone.saturated()) continue;
            ++narrow;
            for (int p = n.first; p < n.first + n.count; ++p) {
              const Face& f = topo.faces()[fresh.prim_ids()[p]];
              const BernsteinNormal b =
                  bernstein_normal(v0[f[0]], v0[f[1]], v0[f[2]], v1[f[0]], v1[f[1]], v1[f[2]]);
              for (int t = 0; t <= 8; ++t) {
                ASSERT_TRUE(contains(cone, b.at(t / 8.0)))
                    << "node " << i << " prim " << p << " t " << t << " call " << call;
              }
            }
          }
          // About as many usable cones as the policy's own (which the first call's `plain` has).
          if (call == 0) {
            int plain_narrow = 0;
            for (std::size_t i = 0; i < nodes.size(); ++i)
              plain_narrow += nodes[i].count >= min && !plain.cones()[i].saturated() ? 1 : 0;
            EXPECT_GE(2 * narrow, plain_narrow);
          }
          total_narrow += narrow;
        }
      }
    }
  }
  EXPECT_GT(total_narrow, 0);
}

// A Bvh owns what its refits read: built from a Topology that is then moved from and destroyed,
// it (and a copy, and a moved tree) refits to the same boxes, cones and contours as a tree whose
// Topology is still alive.
TEST(Bvh, OutlivesItsTopology) {
  const research::ProceduralScene s = research::crumpled_sheet(8, 7);
  const auto v0 = points(s.v_t0), v1 = points(s.v_t1);
  const Topology kept(s.faces, s.num_vertices);
  Bvh reference(kept, v0, BvhBuild::Patch);
  Bvh orphaned, boxes;
  {
    auto gone = std::make_unique<Topology>(s.faces, s.num_vertices);
    orphaned = Bvh(*gone, v0, BvhBuild::Patch);
    boxes = Bvh::boxes_only(*gone, v0, BvhBuild::Patch);
    [[maybe_unused]] const Topology moved_to = std::move(*gone);  // leaves the original empty
    gone.reset();
  }
  Bvh copied = orphaned;
  Bvh moved = std::move(orphaned);
  EXPECT_EQ(moved.faces(), s.faces);
  EXPECT_EQ(moved.num_vertices(), s.num_vertices);
  RefitOptions ro;
  ro.policy = ConePolicy::Exact;
  reference.refit(v0, v1, ro);
  for (Bvh* b : {&copied, &moved}) {
    b->refit(v0, v1, ro);
    ASSERT_EQ(b->nodes().size(), reference.nodes().size());
    for (std::size_t i = 0; i < reference.nodes().size(); ++i) {
      EXPECT_EQ(b->nodes()[i].lo, reference.nodes()[i].lo);
      EXPECT_EQ(b->nodes()[i].hi, reference.nodes()[i].hi);
      EXPECT_EQ(b->nodes()[i].flags, reference.nodes()[i].flags);
      EXPECT_EQ(b->cones()[i].axis, reference.cones()[i].axis);
      EXPECT_EQ(b->cones()[i].half_angle, reference.cones()[i].half_angle);
      const auto c = b->contour(static_cast<int>(i)), r = reference.contour(static_cast<int>(i));
      EXPECT_TRUE(std::equal(c.begin(), c.end(), r.begin(), r.end()));
    }
  }
  // refit_changed looks up the faces of the moved vertices in the tree's own copy.
  auto v1b = v1;
  v1b[3] += Eigen::Vector3d(0.01, 0.02, -0.01);
  moved.refit_changed(v0, v1, ro);
  moved.refit_changed(v0, v1b, ro);
  reference.refit(v0, v1b, ro);
  for (std::size_t i = 0; i < reference.nodes().size(); ++i) {
    EXPECT_EQ(moved.nodes()[i].lo, reference.nodes()[i].lo);
    EXPECT_EQ(moved.nodes()[i].hi, reference.nodes()[i].hi);
  }
  boxes.refit(v0, RefitOptions{});
  EXPECT_EQ(boxes.nodes().size(), reference.nodes().size());
}

// A boxes-only build: the full build's nodes, permutation and boxes, without flags or contours.
TEST(Bvh, BoxesOnlyIsTheSameTreeWithoutFlags) {
  for (const auto& s : {research::stacked_sheets(6), research::crumpled_sheet(8, 7),
                        research::twisted_strip(30, 3)}) {
    const Topology topo(s.faces, s.num_vertices);
    const auto v0 = points(s.v_t0), v1 = points(s.v_t1);
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      SCOPED_TRACE(::testing::Message() << s.name << " build " << int(build));
      Bvh full(topo, v0, build);
      Bvh boxes = Bvh::boxes_only(topo, v0, build);
      RefitOptions ro;
      ro.cones = false;
      full.refit(v0, v1, ro);
      boxes.refit(v0, v1, ro);
      EXPECT_EQ(boxes.prim_ids(), full.prim_ids());
      EXPECT_EQ(boxes.level_offsets(), full.level_offsets());
      ASSERT_EQ(boxes.nodes().size(), full.nodes().size());
      EXPECT_GT(full.num_connected_internal(), 0);
      for (std::size_t i = 0; i < full.nodes().size(); ++i) {
        const BvhNode &a = boxes.nodes()[i], &b = full.nodes()[i];
        EXPECT_EQ(a.lo, b.lo);
        EXPECT_EQ(a.hi, b.hi);
        EXPECT_EQ(a.left, b.left);
        EXPECT_EQ(a.first, b.first);
        EXPECT_EQ(a.count, b.count);
        EXPECT_EQ(a.flags, 0u);
        EXPECT_TRUE(boxes.contour(static_cast<int>(i)).empty());
        EXPECT_EQ(boxes.leaf_of_face(boxes.prim_ids()[a.first]) == static_cast<int>(i),
                  a.is_leaf());
      }
    }
  }
}

// Sibling subtrees are built in parallel (over 2048 faces each): the tree must not depend on the
// threads. Meshes large enough for several parallel levels, one of them in separate pieces (the
// patch build's component split), built on one thread and on eight.
TEST(Bvh, TheSameTreeOnOneThreadAndOnEight) {
  for (const auto& s : {research::crumpled_sheet(100, 5), research::stacked_sheets(70),
                        research::twisted_strip(800, 12)}) {
    const Topology topo(s.faces, s.num_vertices);
    const auto v0 = points(s.v_t0);
    ASSERT_GT(topo.num_faces(), 8 * 2048);  // three levels of parallel splits
    for (BvhBuild build : {BvhBuild::Spatial, BvhBuild::Patch}) {
      SCOPED_TRACE(::testing::Message() << s.name << " build " << int(build));
      const auto built = [&](int threads) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        return Bvh(topo, v0, build);
      };
      const Bvh one = built(1), many = built(8);
      EXPECT_EQ(many.prim_ids(), one.prim_ids());
      EXPECT_EQ(many.level_offsets(), one.level_offsets());
      ASSERT_EQ(many.nodes().size(), one.nodes().size());
      for (std::size_t i = 0; i < one.nodes().size(); ++i) {
        const BvhNode &a = many.nodes()[i], &b = one.nodes()[i];
        ASSERT_EQ(a.left, b.left) << "node " << i;
        ASSERT_EQ(a.first, b.first) << "node " << i;
        ASSERT_EQ(a.count, b.count) << "node " << i;
        ASSERT_EQ(a.flags, b.flags) << "node " << i;
        ASSERT_TRUE(
            std::ranges::equal(many.contour(static_cast<int>(i)), one.contour(static_cast<int>(i))))
            << "node " << i;
      }
    }
  }
}

// The box area ratio: internal over leaf box areas by hand on a two-triangle tree, and its growth
// when a tree built on a folded sheet is refit to the sheet unfolded, against a tree built there.
TEST(Bvh, BoxAreaRatioGrowsAsARefitTreeLoosens) {
  const std::vector<Face> two{{0, 1, 2}, {1, 3, 2}};
  const Topology t2(two, 4);
  const std::vector<Eigen::Vector3d> sq{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  Bvh small(t2, sq, BvhBuild::Spatial);
  RefitOptions ro;
  ro.cones = false;
  small.refit(sq, ro);
  EXPECT_DOUBLE_EQ(small.box_area_ratio(), 0.5);  // root 1 x 1, each leaf 1 x 1
  const std::vector<Eigen::Vector3d> point(4, Eigen::Vector3d(1, 2, 3));
  small.refit(point, ro);
  EXPECT_EQ(small.box_area_ratio(), 1.0);

  // A 24 x 24 grid on the unit square, and the same folded in half (its two halves 2 mm
  // apart): the tree built folded puts faces of both halves in one node, which the unfolding
  // then stretches across the sheet.
  const int n = 24;
  std::vector<Face> faces;
  std::vector<Eigen::Vector3d> flat, folded;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = double(i) / n, y = double(j) / n;
      flat.emplace_back(x, y, 0.0);
      folded.emplace_back(x <= 0.5 ? x : 1.0 - x, y, x <= 0.5 ? 0.0 : 2e-3);
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      faces.push_back({a, a + 1, a + n + 2});
      faces.push_back({a, a + n + 2, a + n + 1});
    }
  }
  const Topology topo(faces, static_cast<int>(flat.size()));
  Bvh old_tree(topo, folded, BvhBuild::Spatial), new_tree(topo, flat, BvhBuild::Spatial);
  old_tree.refit(folded, ro);
  const double built = old_tree.box_area_ratio();
  old_tree.refit(flat, ro);
  new_tree.refit(flat, ro);
  EXPECT_GT(old_tree.box_area_ratio(), 3.0 * built);
  EXPECT_GT(old_tree.box_area_ratio(), 1.5 * new_tree.box_area_ratio());
}

}  // namespace
}  // namespace clothcd
