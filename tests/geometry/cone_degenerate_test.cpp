// Named degenerate cases of the cone algebra: each must give a saturated (or exact) cone and
// never NaN; NaN or infinite input must throw std::invalid_argument.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "clothcd/geometry/cone.hpp"

namespace clothcd {
namespace {

using Eigen::Vector3d;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool well_formed(const NormalCone& c) {
  return c.axis.allFinite() && std::abs(c.axis.norm() - 1.0) < 1e-12 && std::isfinite(c.half_angle);
}

struct LeafCase {
  std::string name;
  Vector3d a0, b0, c0, a1, b1, c1;
  bool saturates;
};

TEST(ConeDegenerate, LeafConeTable) {
  const Vector3d o(0, 0, 0), x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  const std::vector<LeafCase> cases = {
      {"static triangle", o, x, y, o, x, y, false},
      {"translating triangle", o, x, y, o + z, x + z, y + z, false},
      {"collinear at t0", o, x, 2 * x, o, x, y, true},
      {"collinear at t1", o, x, y, o, x, 2 * x, true},
      {"all vertices coincide", o, o, o, o, o, o, true},
      {"collapses to a point", o, x, y, z, z, z, true},
      {"flips over (normal reverses)", o, x, y, o, x, -y, true},
      {"rotates by 90 degrees", o, x, y, o, x, z, false},
      {"rotates by 179 degrees", o, x, y, o, x,
       Vector3d(0, std::cos(179 * std::numbers::pi / 180), std::sin(179 * std::numbers::pi / 180)),
       false},  // the normal turns by 179 degrees without vanishing: a cone just below pi/2
      // Relative area below the rounding of the cross product: the direction is not known.
      {"sliver (relative area 1e-20)", o, x, Vector3d(0.5, 1e-20, 0), o, x, Vector3d(0.5, 1e-20, 0),
       true},
      {"sliver (relative area 1e-12)", o, x, Vector3d(0.5, 1e-12, 0), o, x, Vector3d(0.5, 1e-12, 0),
       false},
      {"huge coordinates", 1e150 * x, 1e150 * (x + y), 1e150 * (x + z), 1e150 * x, 1e150 * (x + y),
       1e150 * (x + z), false},
      {"coordinates that overflow the cross product", 1e300 * x, 1e300 * y, 1e300 * z, 1e300 * x,
       1e300 * y, 1e300 * z, true},
  };
  for (const auto& c : cases) {
    for (const auto policy :
         {LeafConePolicy::Tang, LeafConePolicy::Proposed, LeafConePolicy::Exact}) {
      const NormalCone cone = ccd_leaf_cone(c.a0, c.b0, c.c0, c.a1, c.b1, c.c1, policy);
      EXPECT_TRUE(well_formed(cone)) << c.name;
      EXPECT_EQ(cone.saturated(), c.saturates) << c.name << " policy " << static_cast<int>(policy);
      if (cone.saturated()) {
        EXPECT_EQ(cone.half_angle, kSaturatedHalfAngle) << c.name;
      }
    }
  }
  // Rotating by 90 degrees about the x axis: the normal sweeps a quarter circle, so the cone
  // is at least 45 degrees wide for every policy.
  const NormalCone quarter = ccd_leaf_cone(o, x, y, o, x, z, LeafConePolicy::Exact);
  EXPECT_GE(quarter.half_angle, std::numbers::pi / 4);
}

// Found by fuzz_cones: at t1 the triangle's edges are ~1e-76 long, so the components of its
// normal square into subnormals and a plain norm() is off by 2e-4 (the leaf cone's unit control
// direction was 1.0002 long, and so was the fuzz check's angle). The direction is compared here
// after an underflow-safe normalization.
TEST(ConeDegenerate, TinyNormalAtOneEndIsContained) {
  const Vector3d a0(4.4873686467715366e-88, 1000, -126.28322672022482),
      b0(1000, 8.1149752486733226e-305, 4.4759381595361624e-88),
      c0(6.900123458739809e-305, 1000, 1000),
      a1(-5.3446876474542822e-76, -5.3446876474542822e-76, -5.344235473633789e-76),
      b1(0, 1.3943992169173992e-306, 1.2444070650856668e-85), c1(0, 0, 0);
  Vector3d n1 = (b1 - a1).cross(c1 - a1);
  n1 /= n1.stableNorm();
  for (auto policy : {LeafConePolicy::Tang, LeafConePolicy::Proposed, LeafConePolicy::Exact}) {
    const NormalCone c = ccd_leaf_cone(a0, b0, c0, a1, b1, c1, policy);
    ASSERT_TRUE(well_formed(c));
    if (c.saturated()) continue;
    const double angle = std::atan2(c.axis.cross(n1).norm(), c.axis.dot(n1));
    EXPECT_LE(angle, c.half_angle) << static_cast<int>(policy);
  }
}

TEST(ConeDegenerate, MergeTable) {
  const Vector3d z = Vector3d::UnitZ();
  const NormalCone up{z, 0.1}, down{-z, 0.1}, point{z, 0.0};
  for (const auto merge : {ConeMerge::Provot, ConeMerge::Tight}) {
    SCOPED_TRACE(static_cast<int>(merge));
    // Antiparallel axes: the cross-section is undefined; decided on the scalar.
    EXPECT_TRUE(merge_cones(up, down, merge).saturated());
    EXPECT_TRUE(merge_cones({z, 0.0}, {-z, 0.0}, merge).saturated());
    // A zero axis has no direction.
    EXPECT_TRUE(merge_cones({Vector3d::Zero(), 0.1}, up, merge).saturated());
    EXPECT_TRUE(merge_cones(up, {Vector3d::Zero(), 0.1}, merge).saturated());
    // Saturated inputs saturate, whatever the other cone.
    EXPECT_TRUE(merge_cones({z, std::numbers::pi / 2}, point, merge).saturated());
    EXPECT_TRUE(merge_cones(point, {z, 3.0}, merge).saturated());
    // Identical cones: the same cone (plus slack).
    const NormalCone same = merge_cones(up, up, merge);
    EXPECT_LE(same.half_angle, up.half_angle + 2 * kConeSlack);
    EXPECT_TRUE(contains(same, up));
    // Two cones of exactly pi/4 at pi/2 apart: the merge reaches pi/2 and saturates.
    EXPECT_TRUE(
        merge_cones({z, std::numbers::pi / 4}, {Vector3d::UnitX(), std::numbers::pi / 4}, merge)
            .saturated());
    // A non-unit axis is read as its direction.
    EXPECT_TRUE(contains(merge_cones({3.0 * z, 0.1}, up, merge), up));
    for (const auto& c : {merge_cones(up, down, merge), merge_cones(up, up, merge)}) {
      EXPECT_TRUE(well_formed(c));
    }
  }
  // Tiny but non-zero angle between axes (1e-150 rad): still a finite, containing cone.
  const NormalCone a{z, 1e-3}, b{Vector3d(1e-150, 0, 1).normalized(), 2e-3};
  const NormalCone m = merge_tight(a, b);
  EXPECT_TRUE(well_formed(m));
  EXPECT_TRUE(contains(m, a) && contains(m, b));
}

TEST(ConeDegenerate, OptimalConeTable) {
  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY(), z = Vector3d::UnitZ();
  const std::vector<Vector3d> single = {z};
  EXPECT_LE(optimal_cone(single).half_angle, 2 * kConeSlack);
  const std::vector<Vector3d> antipodal = {z, -z};
  EXPECT_TRUE(optimal_cone(antipodal).saturated());
  const std::vector<Vector3d> great_circle = {x, y, -x};
  EXPECT_TRUE(optimal_cone(great_circle).saturated());
  const std::vector<Vector3d> octahedron = {x, y, z, -x, -y, -z};
  EXPECT_TRUE(optimal_cone(octahedron).saturated());
  const std::vector<Vector3d> with_zero = {x, Vector3d::Zero(), y};
  EXPECT_TRUE(optimal_cone(with_zero).saturated());
  const std::vector<Vector3d> repeated(50, y);
  EXPECT_LE(optimal_cone(repeated).half_angle, 2 * kConeSlack);
  // The three axes: the circumcap around (1,1,1), half-angle acos(1/sqrt 3).
  const std::vector<Vector3d> axes = {x, y, z};
  const NormalCone c = optimal_cone(axes);
  EXPECT_NEAR(c.half_angle, std::acos(1 / std::sqrt(3.0)), 1e-11);
  EXPECT_NEAR(c.axis.dot(Vector3d(1, 1, 1).normalized()), 1.0, 1e-14);
  EXPECT_THROW((void)optimal_cone(std::vector<Vector3d>{}), std::invalid_argument);
}

TEST(ConeDegenerate, DcdTable) {
  const Vector3d o(0, 0, 0), x(1, 0, 0), y(0, 1, 0);
  EXPECT_TRUE(dcd_leaf_cone(o, x, 2 * x).saturated());
  EXPECT_TRUE(dcd_leaf_cone(o, o, o).saturated());
  const NormalCone c = dcd_leaf_cone(o, x, y);
  EXPECT_FALSE(c.saturated());
  EXPECT_NEAR(c.axis.z(), 1.0, 1e-15);
  EXPECT_LE(c.half_angle, 1e-11);
}

TEST(ConeDegenerate, NonFiniteInputThrows) {
  const Vector3d o(0, 0, 0), x(1, 0, 0), y(0, 1, 0);
  for (const double bad : {kNaN, kInf, -kInf}) {
    const Vector3d v(bad, 0, 0);
    EXPECT_THROW((void)merge_provot({v, 0.1}, {x, 0.1}), std::invalid_argument);
    EXPECT_THROW((void)merge_tight({x, 0.1}, {v, 0.1}), std::invalid_argument);
    EXPECT_THROW((void)merge_tight({x, bad}, {x, 0.1}), std::invalid_argument);
    EXPECT_THROW((void)merge_provot({x, 0.1}, {x, bad}), std::invalid_argument);
    for (int slot = 0; slot < 6; ++slot) {
      Vector3d p[6] = {o, x, y, o, x, y};
      p[slot] = v;
      EXPECT_THROW(
          (void)ccd_leaf_cone(p[0], p[1], p[2], p[3], p[4], p[5], LeafConePolicy::Proposed),
          std::invalid_argument)
          << "slot " << slot;
    }
    EXPECT_THROW((void)dcd_leaf_cone(o, v, y), std::invalid_argument);
    const std::vector<Vector3d> set = {x, v};
    EXPECT_THROW((void)optimal_cone(set), std::invalid_argument);
    EXPECT_THROW((void)contains(NormalCone{x, 0.1}, v), std::invalid_argument);
  }
  EXPECT_THROW((void)merge_tight({x, -0.1}, {x, 0.1}), std::invalid_argument);
  // The message names the function and the argument.
  try {
    (void)ccd_leaf_cone(o, x, y, o, Vector3d(kNaN, 0, 0), y, LeafConePolicy::Tang);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ccd_leaf_cone"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("b_t1"), std::string::npos);
  }
}

}  // namespace
}  // namespace clothcd
