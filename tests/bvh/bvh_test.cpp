// BVH structure against brute force: permutation ranges, boxes enclosing their triangles, the
// connectivity flag against a breadth-first search, disks with one consistent boundary loop.

#include <gtest/gtest.h>

#include <numeric>
#include <set>

#include "clothcd/bvh/bvh.hpp"
#include "clothcd/detect/procedural.hpp"

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
  for (const auto& s :
       {stacked_sheets(6), winding_strip(40, 2), crumpled_sheet(8, 7), twisted_strip(30, 3)}) {
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

// refit_changed over a sequence of calls (a few vertices moved, a static refit between, other
// options) gives after every call, bit for bit, the boxes and cones of a fresh full refit, for
// every cone policy.
TEST(Bvh, RefitChangedEqualsFullRefitAfterEveryCall) {
  for (const auto& s : {crumpled_sheet(8, 7), twisted_strip(30, 3), stacked_sheets(6)}) {
    const Topology topo(s.faces, s.num_vertices);
    const auto v0 = points(s.v_t0);
    for (ConePolicy policy :
         {ConePolicy::Provot, ConePolicy::Proposed, ConePolicy::Exact, ConePolicy::Optimal}) {
      SCOPED_TRACE(::testing::Message() << s.name << " policy " << int(policy));
      auto v1 = points(s.v_t1);
      Bvh reused(topo, v0, BvhBuild::Spatial);
      RefitOptions ro;
      ro.policy = policy;
      ro.thickness = 1e-3;
      for (int call = 0; call < 6; ++call) {
        if (call == 3) reused.refit(v0, ro);  // static: the next call starts over
        if (call == 4) ro.thickness = 2e-3;   // other options: likewise
        if (call > 0) {
          for (std::size_t v = call; v < v1.size(); v += 11)
            v1[v] += Eigen::Vector3d(0.02 * call, -0.01, 0.03);
        }
        reused.refit_changed(v0, v1, ro);
        Bvh fresh(topo, v0, BvhBuild::Spatial);
        fresh.refit(v0, v1, ro);
        for (std::size_t i = 0; i < fresh.nodes().size(); ++i) {
          for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(reused.nodes()[i].lo[k], fresh.nodes()[i].lo[k]) << "call " << call;
            ASSERT_EQ(reused.nodes()[i].hi[k], fresh.nodes()[i].hi[k]) << "call " << call;
          }
          ASSERT_EQ(reused.cones()[i].axis, fresh.cones()[i].axis) << "call " << call;
          ASSERT_EQ(reused.cones()[i].half_angle, fresh.cones()[i].half_angle) << "call " << call;
        }
      }
    }
  }
}

}  // namespace
}  // namespace clothcd
