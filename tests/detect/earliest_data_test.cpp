// cloth_ball 92 -> 93: the earliest impact against the exact rational oracle. No VF or EE pair
// touches before the reported time (checked exactly on every pair the kernels could time that
// early: the others' kernels, never late, place any contact later), the reported pair touches
// within the tolerance after it, and the answer is the same for every window and thread count.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "clothcd/ccd/queries.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/io.hpp"
#include "exact_oracle.hpp"
#include "support/data.hpp"

namespace clothcd {
namespace earliest_data_test {

using Kind = EarliestImpact::Kind;

TEST(EarliestImpactData, ClothBallAgainstTheExactOracle) {
  CLOTHCD_REQUIRE_DATA(root, "cloth-ball");
  const TriangleMesh m0 = read_mesh(root / "frames/cloth_ball92.ply");
  const TriangleMesh m1 = read_mesh(root / "frames/cloth_ball93.ply");
  const Positions p0 = vertices_matrix(m0), p1 = vertices_matrix(m1);
  SelfDetector det(m0.faces, m0.num_vertices(), p0);
  const double tol = 1e-6;
  const EarliestImpact e = det.earliest_impact(p0, p1);
  ASSERT_NE(e.kind, Kind::None);
  ASSERT_GT(e.toi, 0.0);
  EXPECT_EQ(e.windows, 1);
  EXPECT_LT(e.first_window, 1.0);

  // Every pair the full detection times by e.toi + tol (its kernels are never late, so no other
  // pair touches that early): none touches, exactly, before e.toi.
  DetectOptions o;
  o.toi_tolerance = tol;
  det.set_options(o);
  const DetectResult all = det.detect(p0, p1);
  const Topology& t = det.topology();
  const auto row = [](const Positions& p, int v) { return Eigen::Vector3d(p.row(v)); };
  const auto vf_query = [&](int v, int f) {
    const Face& x = t.faces()[f];
    return VertexFaceQuery{row(p0, v), row(p0, x[0]), row(p0, x[1]), row(p0, x[2]),
                           row(p1, v), row(p1, x[0]), row(p1, x[1]), row(p1, x[2])};
  };
  const auto ee_query = [&](int i, int j) {
    const Edge &a = t.edges()[i], &b = t.edges()[j];
    return EdgeEdgeQuery{row(p0, a[0]), row(p0, a[1]), row(p0, b[0]), row(p0, b[1]),
                         row(p1, a[0]), row(p1, a[1]), row(p1, b[0]), row(p1, b[1])};
  };
  const double before = std::nextafter(e.toi, 0.0);
  int checked = 0;
  for (const VertexFaceCollision& c : all.vf) {
    if (c.toi > e.toi + tol) continue;
    ++checked;
    EXPECT_FALSE(test::exact_vertex_face_contact(vf_query(c.vertex, c.face), before))
        << "vertex " << c.vertex << " face " << c.face;
  }
  for (const EdgeEdgeCollision& c : all.ee) {
    if (c.toi > e.toi + tol) continue;
    ++checked;
    EXPECT_FALSE(test::exact_edge_edge_contact(ee_query(c.edge_a, c.edge_b), before))
        << "edges " << c.edge_a << " " << c.edge_b;
  }
  EXPECT_GT(checked, 0);
  // The reported pair does touch, within the tolerance after the reported time.
  const double by = e.toi + tol;
  if (e.kind == Kind::VertexFace) {
    EXPECT_TRUE(test::exact_vertex_face_contact(vf_query(e.ids[0], e.ids[1]), by));
  } else {
    EXPECT_TRUE(test::exact_edge_edge_contact(ee_query(e.ids[0], e.ids[1]), by));
  }

  // The same answer from the whole step as one window, and on one thread.
  det.set_options({});
  EarliestOptions whole;
  whole.first_window = 1;
  const EarliestImpact w = det.earliest_impact(p0, p1, whole);
  EXPECT_EQ(w.toi, e.toi);
  EXPECT_EQ(w.kind, e.kind);
  EXPECT_EQ(w.ids, e.ids);
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const EarliestImpact s = det.earliest_impact(p0, p1);
  EXPECT_EQ(s.toi, e.toi);
  EXPECT_EQ(s.ids, e.ids);
}

}  // namespace earliest_data_test
}  // namespace clothcd
