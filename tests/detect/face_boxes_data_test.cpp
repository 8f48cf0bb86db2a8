// The pair loop's box blocks on cloth_ball 92 -> 93: for the triangle pairs around every
// candidate pair of the broad phase data (each face of one feature against each face of the
// other, sharing no vertex), the same overlaps and the same feature pairs, in the same order, as
// the separate boxes, with and without a margin.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <span>
#include <vector>

#include "clothcd/mesh/io.hpp"
#include "detect/step_positions.hpp"
#include "face_boxes_check.hpp"
#include "support/data.hpp"
#include "support/json_file.hpp"

namespace clothcd::face_boxes_data_test {
namespace {

using test::read_json;

TEST(FaceBoxes, SameFeaturePairsAsTheSeparateBoxesOnClothBall) {
  CLOTHCD_REQUIRE_DATA(root, "cloth-ball");
  const TriangleMesh m0 = read_mesh(root / "frames/cloth_ball92.ply");
  const TriangleMesh m1 = read_mesh(root / "frames/cloth_ball93.ply");
  const int nv = m0.num_vertices();
  const Topology t(m0.faces, nv);
  const int ne = t.num_edges();
  std::vector<Eigen::Vector3d> x0, x1;
  for (int i = 0; i < nv; ++i) {
    x0.push_back(m0.vertices[i]);
    x1.push_back(m1.vertices[i]);
  }
  // Triangle pairs around the candidates (ids as in the data README).
  std::vector<std::pair<int, int>> pairs;
  const auto add = [&](std::span<const int> fa, std::span<const int> fb) {
    for (int f : fa) {
      for (int g : fb) {
        if (!detail::share_vertex(t.faces()[f], t.faces()[g])) pairs.emplace_back(f, g);
      }
    }
  };
  for (const auto& p : read_json(root / "boxes/92vf.json")) {
    const int v = p[0].get<int>(), f = p[1].get<int>() - nv - ne;
    add(t.vertex_faces(v), std::span<const int>(&f, 1));
  }
  for (const auto& p : read_json(root / "boxes/92ee.json"))
    add(t.edge_faces(p[0].get<int>() - nv), t.edge_faces(p[1].get<int>() - nv));
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  ASSERT_GT(pairs.size(), 100000u);

  const detail::Ownership owner(t);
  detail::FeatureBoxes boxes(true);
  detail::StepPositions step;
  step.update(std::span<const Eigen::Vector3d>(x0), std::span<const Eigen::Vector3d>(x1), nv, "t0",
              "t1");
  for (double margin : {0.0, 5e-4}) {
    SCOPED_TRACE(::testing::Message() << "margin " << margin);
    detail::FeatureContext ctx = face_boxes_check::step_context(t, step, margin);
    boxes.update(ctx, step);
    face_boxes_check::expect_blocks(ctx);
    std::size_t n = 0;
    for (auto [f, g] : pairs) {
      n += face_boxes_check::check_pair(owner, ctx, f, g);
      n += face_boxes_check::check_pair(owner, ctx, g, f);
      if (::testing::Test::HasFailure()) return;
    }
    EXPECT_GT(n, 100000u);
  }
}

}  // namespace
}  // namespace clothcd::face_boxes_data_test
