// The narrow phase's kept feature boxes (detail::FeatureBoxes) against each feature's own swept
// box: bit for bit, with and without a margin, after a full update, after an update where a few
// vertices moved, and after calls the boxes did not see; and the changed-vertex flags they use
// (detail::StepPositions).
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/research/procedural.hpp"
#include "detect/narrow.hpp"
#include "detect/step_positions.hpp"
#include "face_boxes_check.hpp"

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
  const research::ProceduralScene s = research::crumpled_sheet(9, 3);
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
  detail::StepPositions step;
  const auto call = [&] {
    step.update(std::span<const Eigen::Vector3d>(v0), std::span<const Eigen::Vector3d>(v1),
                s.num_vertices, "t0", "t1");
  };
  for (double margin : {0.0, 5e-6, 5e-4}) {
    SCOPED_TRACE(::testing::Message() << "margin " << margin);
    call();
    detail::FeatureContext ctx = face_boxes_check::step_context(topo, step, margin);
    boxes.update(ctx, step);
    expect_own_boxes(ctx);
    // A few vertices move: only their features' boxes are redone, and all still agree.
    for (int i = 0; i < s.num_vertices; i += 11)
      v1[i] += Eigen::Vector3d(u(rng), u(rng), u(rng));
    call();
    boxes.update(ctx, step);
    expect_own_boxes(ctx);
    // A call the boxes did not see (its changes are not the latest call's): all are redone.
    for (int i = 3; i < s.num_vertices; i += 7)
      v0[i] += Eigen::Vector3d(u(rng), u(rng), u(rng));
    call();
    v1[5] += Eigen::Vector3d(u(rng), u(rng), u(rng));
    call();
    boxes.update(ctx, step);
    expect_own_boxes(ctx);
  }
}

TEST(StepPositions, FlagsTheVerticesThatChangedSinceThePreviousCall) {
  std::vector<Eigen::Vector3d> a(4, Eigen::Vector3d::Zero()), b = a;
  detail::StepPositions step;
  EXPECT_EQ(step.call(), 0u);
  step.update(std::span<const Eigen::Vector3d>(a), std::span<const Eigen::Vector3d>(b), 4, "a",
              "b");
  EXPECT_TRUE(step.changed_since(0).empty());  // no earlier call: everything counts as changed
  b[2].x() = 1.0;
  step.update(std::span<const Eigen::Vector3d>(a), std::span<const Eigen::Vector3d>(b), 4, "a",
              "b");
  const auto changed = step.changed_since(1);
  ASSERT_EQ(changed.size(), 4u);
  EXPECT_EQ(std::vector<std::uint8_t>(changed.begin(), changed.end()),
            (std::vector<std::uint8_t>{0, 0, 1, 0}));
  EXPECT_TRUE(step.changed_since(0).empty());                       // two calls ago: unknown
  step.update_static(std::span<const Eigen::Vector3d>(a), 4, "a");  // t1 = t0 again
  EXPECT_EQ(std::vector<std::uint8_t>(step.changed_since(2).begin(), step.changed_since(2).end()),
            (std::vector<std::uint8_t>{0, 0, 1, 0}));
  // A bad call throws and leaves the positions and the flags as they were.
  a[1].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(step.update_static(std::span<const Eigen::Vector3d>(a), 4, "a"), InputError);
  EXPECT_EQ(step.call(), 3u);
  EXPECT_EQ(step.x0()[1], Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace clothcd
