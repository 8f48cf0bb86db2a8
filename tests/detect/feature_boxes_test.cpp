// The narrow phase's kept feature boxes (detail::FeatureBoxes) against each feature's own swept
// box: bit for bit, with and without a margin, after a full update and after an update where a
// few vertices moved.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "clothcd/detect/procedural.hpp"
#include "detect/narrow.hpp"

namespace clothcd {
namespace {

bool same(const detail::Box& a, const detail::Box& b) {
  return std::memcmp(&a, &b, sizeof(detail::Box)) == 0;
}

void expect_own_boxes(const detail::FeatureContext& ctx) {
  const Topology& t = *ctx.topo;
  for (int v = 0; v < t.num_vertices(); ++v)
    ASSERT_TRUE(same(ctx.vboxes[v], ctx.compute_vertex_box(v))) << "vertex " << v;
  for (int e = 0; e < t.num_edges(); ++e)
    ASSERT_TRUE(same(ctx.eboxes[e], ctx.compute_edge_box(e))) << "edge " << e;
  for (int f = 0; f < t.num_faces(); ++f)
    ASSERT_TRUE(same(ctx.fboxes[f], ctx.compute_face_box(f))) << "face " << f;
}

TEST(FeatureBoxes, EqualEachFeaturesOwnSweptBox) {
  const ProceduralScene s = crumpled_sheet(9, 3);
  const Topology topo(s.faces, s.num_vertices);
  std::vector<Eigen::Vector3d> v0(s.num_vertices), v1(s.num_vertices);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<> u(-1e-3, 1e-3);
  for (int i = 0; i < s.num_vertices; ++i) {
    // Far from the origin, where float rounding of the boxes is coarse.
    v0[i] = s.v_t0.row(i).transpose() + Eigen::Vector3d(100.3, -7.1, 0.2);
    v1[i] = s.v_t1.row(i).transpose() + Eigen::Vector3d(100.3, -7.1, 0.2);
  }
  detail::FeatureBoxes boxes;
  for (double margin : {0.0, 5e-6, 5e-4}) {
    SCOPED_TRACE(::testing::Message() << "margin " << margin);
    detail::FeatureContext ctx;
    ctx.topo = &topo;
    ctx.v0 = v0;
    ctx.v1 = v1;
    ctx.margin = margin;
    boxes.update(ctx);
    expect_own_boxes(ctx);
    // A few vertices move: only their features' boxes are redone, and all still agree.
    for (int i = 0; i < s.num_vertices; i += 11)
      v1[i] += Eigen::Vector3d(u(rng), u(rng), u(rng));
    boxes.update(ctx);
    expect_own_boxes(ctx);
  }
}

}  // namespace
}  // namespace clothcd
