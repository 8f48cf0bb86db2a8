// The collision stage on hand-built approaches: CCD impulses stop a crossing, repulsion separates
// gently, the body has infinite mass. (Whole scenes: collision_scenes_test.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/detect/detector.hpp"
#include "clothcd/sim/contact_handler.hpp"
#include "clothcd/sim/intersections.hpp"

namespace clothcd::sim {
namespace {

Vec3 total_momentum(const ClothModel& m, const std::vector<Vec3>& v) {
  Vec3 p = Vec3::Zero();
  for (int i = 0; i < m.num_vertices(); ++i)
    p += m.mass()[i] * v[i];
  return p;
}

// One substep of the handler alone: x1 = x0 + h v* after respond.
struct OneStep {
  std::vector<Vec3> x1, v;
  CollisionStats stats;
};

// The context of one substep from the model's initial positions (the body still when body_t1 is
// empty). Not copyable: the context points into `inv`.
struct HandlerSubstep {
  std::vector<double> inv;
  SubstepContext ctx;
  HandlerSubstep(const ClothModel& m, double h, const std::vector<Vec3>& body,
                 const std::vector<Face>* body_faces, const std::vector<Vec3>& body_t1) {
    for (double mass : m.mass())
      inv.push_back(1.0 / mass);
    ctx.h = h;
    ctx.x0 = m.initial_positions();
    ctx.inverse_mass = inv;
    ctx.cloth = &m.topology();
    ctx.body_t0 = body;
    ctx.body_t1 = body_t1.empty() ? body : body_t1;
    ctx.body_faces = body_faces;
  }
  HandlerSubstep(const HandlerSubstep&) = delete;
  HandlerSubstep& operator=(const HandlerSubstep&) = delete;
};

OneStep one_step(const ClothModel& m, std::vector<Vec3> v, double h,
                 const std::vector<Vec3>& body = {}, const std::vector<Face>* body_faces = nullptr,
                 const std::vector<Vec3>& body_t1 = {}, const ContactOptions& options = {}) {
  const HandlerSubstep sub(m, h, body, body_faces, body_t1);
  const SubstepContext& ctx = sub.ctx;
  ContactHandler handler(m, options);
  handler.prepare(ctx);
  OneStep out;
  out.stats = handler.respond(ctx, v);
  out.v = v;
  for (int i = 0; i < m.num_vertices(); ++i)
    out.x1.push_back(m.initial_positions()[i] + h * v[i]);
  return out;
}

Positions to_matrix(const std::vector<Vec3>& x) {
  Positions p(static_cast<Eigen::Index>(x.size()), 3);
  for (std::size_t i = 0; i < x.size(); ++i)
    p.row(static_cast<Eigen::Index>(i)) = x[i].transpose();
  return p;
}

// Two horizontal triangles, the upper one (vertices 3-5) falling 2 cm through the lower one in a
// 1 cm... within one substep.
ClothMeshInput two_triangles(double gap) {
  ClothMeshInput in;
  in.positions = {{0, 0, 0},       {1, 0, 0},       {0, 0, 1},
                  {0.2, gap, 0.2}, {0.6, gap, 0.2}, {0.2, gap, 0.6}};
  in.faces = {{0, 2, 1}, {3, 5, 4}};
  return in;
}

TEST(CollisionStats, AddsEveryFigureAndKeepsTheLargestZone) {
  CollisionStats a{.proximity_pairs = 1,
                   .ccd_hits = 2,
                   .ccd_passes = 3,
                   .zones = 4,
                   .largest_zone = 9,
                   .zone_rounds = 5,
                   .unresolved = 6,
                   .excluded = 7,
                   .seconds = 0.5};
  const CollisionStats b{.proximity_pairs = 10,
                         .ccd_hits = 20,
                         .ccd_passes = 30,
                         .zones = 40,
                         .largest_zone = 8,
                         .zone_rounds = 50,
                         .unresolved = 60,
                         .excluded = 70,
                         .seconds = 0.25};
  a += b;
  EXPECT_EQ(a.proximity_pairs, 11);
  EXPECT_EQ(a.ccd_hits, 22);
  EXPECT_EQ(a.ccd_passes, 33);
  EXPECT_EQ(a.zones, 44);
  EXPECT_EQ(a.largest_zone, 9);
  EXPECT_EQ(a.zone_rounds, 55);
  EXPECT_EQ(a.unresolved, 66);
  EXPECT_EQ(a.excluded, 77);
  EXPECT_EQ(a.seconds, 0.75);
  CollisionStats c = b;
  c += CollisionStats{.largest_zone = 12};
  EXPECT_EQ(c.largest_zone, 12);
  EXPECT_EQ(c.ccd_hits, 20);
}

TEST(ContactHandler, StopsTwoTrianglesCrossing) {
  const ClothModel m(two_triangles(0.01), ClothMaterial{});
  std::vector<Vec3> v(6, Vec3::Zero());
  for (int i = 3; i < 6; ++i)
    v[i] = Vec3(0.3, -2.0, 0.1);  // 2 cm down in 1 cm of gap, with a sliding component
  const double h = 0.01;
  // Without a handler the motion crosses.
  {
    std::vector<Vec3> x1;
    for (int i = 0; i < 6; ++i)
      x1.push_back(m.initial_positions()[i] + h * v[i]);
    SelfDetector d(m.topology().faces(), 6, to_matrix(m.initial_positions()));
    const DetectResult r = d.detect(to_matrix(m.initial_positions()), to_matrix(x1));
    ASSERT_FALSE(r.vf.empty() && r.ee.empty());
  }
  const Vec3 p0 = total_momentum(m, v);
  const OneStep s = one_step(m, v, h);
  EXPECT_GT(s.stats.ccd_hits, 0);
  // Nothing crosses along the corrected motion, and the upper triangle stays above.
  SelfDetector d(m.topology().faces(), 6, to_matrix(m.initial_positions()));
  const DetectResult r = d.detect(to_matrix(m.initial_positions()), to_matrix(s.x1));
  EXPECT_TRUE(r.vf.empty());
  EXPECT_TRUE(r.ee.empty());
  for (int i = 3; i < 6; ++i)
    EXPECT_GT(s.x1[i].y(), s.x1[0].y());
  // Pair impulses are internal: momentum is unchanged.
  EXPECT_LT((total_momentum(m, s.v) - p0).norm(), 1e-12);
}

// The strain limiter's hook: called once before the first CCD pass with nothing flagged, then
// after each projection with the vertices it changed; what the hook moves, before the first pass
// or after a projection, is tested by the passes that follow, so the motion stays crossing-free.
TEST(ContactHandler, HookRunsBeforeTheFirstPassAndAfterEachProjection) {
  const ClothModel m(two_triangles(0.01), ClothMaterial{});
  const double h = 0.01;
  std::vector<Vec3> v(6, Vec3::Zero());  // at rest: only the hook makes them move
  const HandlerSubstep sub(m, h, {}, nullptr, {});
  SubstepContext ctx = sub.ctx;
  std::vector<int> flagged_per_call;
  ctx.after_projection = [&](std::span<Vec3> vh, std::span<std::uint8_t> touched) {
    flagged_per_call.push_back(
        static_cast<int>(std::count(touched.begin(), touched.end(), std::uint8_t{1})));
    if (flagged_per_call.size() == 1) {
      // Before the first pass: send the upper triangle 2 cm down through the lower one.
      for (int i = 3; i < 6; ++i)
        vh[i] = Vec3(0.3, -2.0, 0.1);
    } else if (flagged_per_call.size() == 2) {
      // After the first projection: push vertex 3 down again, and flag it.
      vh[3] = Vec3(0.0, -2.0, 0.0);
      touched[3] = 1;
    }
  };
  ContactHandler handler(m, ContactOptions{});
  handler.prepare(ctx);
  const CollisionStats st = handler.respond(ctx, v);
  ASSERT_GE(flagged_per_call.size(), 2u);
  EXPECT_EQ(flagged_per_call[0], 0);
  EXPECT_GT(flagged_per_call[1], 0);
  EXPECT_EQ(static_cast<int>(flagged_per_call.size()), st.ccd_passes);  // + 1 before, - 1 clean
  EXPECT_GT(st.ccd_hits, 0);
  EXPECT_EQ(st.unresolved, 0);
  std::vector<Vec3> x1;
  for (int i = 0; i < 6; ++i)
    x1.push_back(m.initial_positions()[i] + h * v[i]);
  SelfDetector d(m.topology().faces(), 6, to_matrix(m.initial_positions()));
  const DetectResult r = d.detect(to_matrix(m.initial_positions()), to_matrix(x1));
  EXPECT_TRUE(r.vf.empty());
  EXPECT_TRUE(r.ee.empty());
  for (int i = 3; i < 6; ++i)
    EXPECT_GT(x1[i].y(), x1[0].y());
}

TEST(ContactHandler, RepelsWithinThicknessWithoutPopping) {
  const ClothModel m(two_triangles(0.0005), ClothMaterial{});  // 0.5 mm apart, inside 1 mm
  const std::vector<Vec3> v(6, Vec3::Zero());
  const OneStep s = one_step(m, v, 0.01);
  EXPECT_GT(s.stats.proximity_pairs, 0);
  // They separate gently: each pair removes 10% of its overlap per substep; Gauss-Seidel over
  // the three vertex-face pairs sharing the lower face adds a little.
  const double gap = s.x1[3].y() - s.x1[0].y();
  EXPECT_GT(gap, 0.0005);
  EXPECT_LT(gap, 0.0005 + 0.2 * 0.0005);
}

TEST(ContactHandler, BodyHasInfiniteMass) {
  // Vertices 0-2 are a body triangle; the cloth is the upper triangle alone.
  ClothMeshInput in;
  in.positions = {{0.2, 0.01, 0.2}, {0.6, 0.01, 0.2}, {0.2, 0.01, 0.6}};
  in.faces = {{0, 2, 1}};
  const ClothModel m(in, ClothMaterial{});
  const std::vector<Vec3> body = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  const std::vector<Face> body_faces = {{0, 2, 1}};
  // The body rises 5 mm while the cloth falls 2 cm.
  std::vector<Vec3> body1 = body;
  for (Vec3& b : body1)
    b.y() += 0.005;
  std::vector<Vec3> v(3, Vec3(0, -2.0, 0));
  const OneStep s = one_step(m, v, 0.01, body, &body_faces, body1);
  EXPECT_GT(s.stats.ccd_hits, 0);
  for (const Vec3& x : s.x1)
    EXPECT_GT(x.y(), 0.005);  // above the body's end position
  IntersectionCounter c(m.topology(), {}, body_faces, 3);
  EXPECT_TRUE(c.body_pairs(s.x1, body1).empty());
}

// What a handler hands the dynamics solve after prepare() with the cloth at rest.
struct SolveContacts {
  std::vector<ContactConstraint> constraints;
  std::vector<ContactCoupling> couplings;
};
SolveContacts solve_contacts(const ClothModel& m, double h, const std::vector<Vec3>& body,
                             const std::vector<Face>* body_faces, const std::vector<Vec3>& body_t1,
                             const ContactOptions& o) {
  const HandlerSubstep sub(m, h, body, body_faces, body_t1);
  ContactHandler handler(m, o);
  handler.prepare(sub.ctx);
  SolveContacts out;
  handler.contact_constraints(out.constraints);
  handler.contact_couplings(out.couplings);
  return out;
}

// A cloth triangle resting 0.5 mm above a body triangle that rises at 0.1 m/s.
struct RestingOnRisingBody {
  ClothModel cloth;
  std::vector<Vec3> body0 = {{-1, 0, -1}, {2, 0, -1}, {-1, 0, 2}};
  std::vector<Vec3> body1;
  std::vector<Face> body_faces = {{0, 2, 1}};
  double h = 0.01;
  RestingOnRisingBody() : cloth(one_triangle(0.0005), ClothMaterial{}) {
    body1 = body0;
    for (Vec3& b : body1)
      b.y() += 0.1 * h;
  }
  static ClothMeshInput one_triangle(double y) {
    ClothMeshInput in;
    in.positions = {{0.2, y, 0.2}, {0.6, y, 0.2}, {0.2, y, 0.6}};
    in.faces = {{0, 2, 1}};
    return in;
  }
  [[nodiscard]] std::vector<ContactConstraint> constraints(const ContactOptions& o) const {
    return solve_contacts(cloth, h, body0, &body_faces, body1, o).constraints;
  }
};

TEST(ContactHandler, ClothVerticesOnTheBodyBecomeConstraintsOfTheSolve) {
  const RestingOnRisingBody s;
  ContactOptions o;
  const std::vector<ContactConstraint> c = s.constraints(o);
  ASSERT_EQ(c.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(c[i].vertex, i);
    EXPECT_NEAR((c[i].n - Vec3(0, 1, 0)).norm(), 0.0, 1e-12);
    // The body's normal velocity plus the repulsion target 0.1 (1 mm - 0.5 mm) / h.
    EXPECT_NEAR(c[i].normal_velocity, 0.1 + 0.1 * 0.0005 / s.h, 1e-9);
  }
  o.body_constraints = false;
  EXPECT_TRUE(s.constraints(o).empty());
}

// A cloth triangle falling at 1 m/s: vertex 0 rests 0.5 mm above a small body plate, and a body
// spike stands 0.5 mm under the face near vertex 0, while vertices 1 and 2 are far from the body.
struct FaceOnSpike {
  ClothModel cloth;
  std::vector<Vec3> body = {{-0.01, 0.0095, -0.01}, {0.01, 0.0095, -0.01}, {-0.01, 0.0095, 0.01},
                            {0.02, 0.0095, 0.02},   {0.03, -0.05, 0.02},   {0.02, -0.05, 0.03}};
  std::vector<Face> body_faces = {{0, 2, 1}, {3, 5, 4}};
  FaceOnSpike() : cloth(triangle(), ClothMaterial{}) {}
  static ClothMeshInput triangle() {
    ClothMeshInput in;
    in.positions = {{0, 0.01, 0}, {0.1, 0.01, 0}, {0, 0.01, 0.1}};
    in.faces = {{0, 2, 1}};
    return in;
  }
};

std::vector<ContactCoupling> couplings_at(const ClothModel& m, double h,
                                          const std::vector<Vec3>& body,
                                          const std::vector<Face>* body_faces,
                                          const ContactOptions& o) {
  return solve_contacts(m, h, body, body_faces, {}, o).couplings;
}

TEST(ContactHandler, ClothLayersInContactBecomeCouplingsOfTheSolve) {
  // Two separate horizontal triangles 0.5 mm apart, the upper inside the lower in x and z.
  ClothMeshInput in;
  in.positions = {{0, 0, 0},          {0.1, 0, 0},        {0, 0, 0.1},
                  {0.02, 5e-4, 0.02}, {0.06, 5e-4, 0.02}, {0.02, 5e-4, 0.06}};
  in.faces = {{0, 2, 1}, {3, 5, 4}};
  const ClothModel m(in, ClothMaterial{});
  const double h = 0.01;
  ContactOptions o;
  const std::vector<ContactCoupling> k = couplings_at(m, h, {}, nullptr, o);
  // The upper vertices over the lower face; no edge of one is within 1 mm of an edge of the other.
  ASSERT_EQ(k.size(), 3u);
  for (int j = 0; j < 3; ++j) {
    EXPECT_EQ(k[j].vertex[0], 3 + j);
    EXPECT_EQ((std::array<int, 3>{k[j].vertex[1], k[j].vertex[2], k[j].vertex[3]}),
              (std::array<int, 3>{0, 2, 1}));
    EXPECT_NEAR((k[j].n - Vec3(0, 1, 0)).norm(), 0.0, 1e-12);
    EXPECT_NEAR(k[j].c[0] + k[j].c[1] + k[j].c[2] + k[j].c[3], 0.0, 1e-12);
    EXPECT_EQ(k[j].body_velocity, 0.0);
    EXPECT_NEAR(k[j].normal_velocity, 0.1 * 0.0005 / h, 1e-9);  // the repulsion target
  }
  o.coupled_contacts = false;
  EXPECT_TRUE(couplings_at(m, h, {}, nullptr, o).empty());
}

TEST(ContactHandler, BodyVerticesAndEdgesNearTheClothBecomeCouplingsWithTheBodySideFixed) {
  const FaceOnSpike s;
  ContactOptions o;
  const std::vector<ContactCoupling> k = couplings_at(s.cloth, 0.005, s.body, &s.body_faces, o);
  // The spike's tip (body vertex 3) under the face: the face's vertices against a body point
  // below them.
  int spike = 0;
  for (const ContactCoupling& c : k) {
    EXPECT_NEAR(c.c[0] + c.c[1] + c.c[2] + c.c[3], 0.0, 1e-12);
    EXPECT_EQ(c.body_velocity, 0.0);  // the body stands still
    EXPECT_TRUE(c.vertex[0] >= 0 || c.vertex[1] >= 0 || c.vertex[2] >= 0 || c.vertex[3] >= 0);
    if (c.vertex == std::array<int, 4>{-1, 0, 2, 1}) {
      ++spike;
      EXPECT_NEAR((c.n - Vec3(0, -1, 0)).norm(), 0.0, 1e-12);
      EXPECT_NEAR(c.normal_velocity, 0.1 * 0.0005 / 0.005, 1e-9);
    }
  }
  EXPECT_EQ(spike, 1);
  // Cloth vertex 0 over the plate is a constraint, not a coupling.
  for (const ContactCoupling& c : k)
    EXPECT_FALSE(c.vertex[0] == 0 && c.vertex[1] < 0 && c.vertex[2] < 0 && c.vertex[3] < 0);
  o.coupled_contacts = false;
  EXPECT_TRUE(couplings_at(s.cloth, 0.005, s.body, &s.body_faces, o).empty());
}

TEST(ContactHandler, RepulsionDoesNotThrowARestingVertexOffTheBody) {
  const FaceOnSpike s;
  const std::vector<Vec3> v(3, Vec3(0, -1.0, 0));
  ContactOptions o;
  o.body_constraints = false;  // the response alone
  const OneStep pw = one_step(s.cloth, v, 0.005, s.body, &s.body_faces, {}, o);
  EXPECT_GT(pw.stats.proximity_pairs, 0);
  // Every vertex stops falling onto the body and none leaves it faster than repulsion asks.
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(pw.v[i].y(), -1e-9) << i;
    EXPECT_LT(pw.v[i].y(), 0.05) << i;
  }
  // One impulse per contact, spread by weight, throws vertex 0 (weight 0.6 at the spike) up.
  o.pointwise_repulsion = false;
  const OneStep one = one_step(s.cloth, v, 0.005, s.body, &s.body_faces, {}, o);
  EXPECT_GT(one.v[0].y(), 0.2);
}

TEST(ContactHandler, RestingPairInsideTheSeparationIsNotAHit) {
  // 5 um apart (inside the 10 um CCD separation), sliding together: the pair never approaches,
  // so it is not a CCD hit (it used to be one at toi 0 in every pass and zone round).
  const ClothModel m(two_triangles(5e-6), ClothMaterial{});
  const std::vector<Vec3> v(6, Vec3(0.4, 0.0, -0.2));
  const OneStep s = one_step(m, v, 0.01);
  EXPECT_GT(s.stats.proximity_pairs, 0);
  EXPECT_EQ(s.stats.ccd_hits, 0);
  EXPECT_EQ(s.stats.zone_rounds, 0);
  for (int i = 3; i < 6; ++i)
    EXPECT_GT(s.x1[i].y(), s.x1[0].y());  // still above
}

TEST(ContactHandler, PairsAlreadyCrossingAreLeftOutNotFought) {
  // A lower triangle (0-2), a triangle (3-5) already crossing it whose lower vertex rises through
  // it, and a triangle (6-8) falling onto it. CCD cannot undo the crossing, so the pairs of the
  // crossing faces are left out (counted) instead of filling every zone round; the falling
  // triangle is still stopped.
  ClothMeshInput in;
  in.positions = {{0, 0, 0},         {1, 0, 0},        {0, 0, 1},          // lower
                  {0.1, -0.05, 0.5}, {0.3, 0.05, 0.5}, {0.1, 0.05, 0.8},   // crossing
                  {0.5, 0.01, 0.1},  {0.8, 0.01, 0.1}, {0.5, 0.01, 0.4}};  // falling
  in.faces = {{0, 2, 1}, {3, 5, 4}, {6, 8, 7}};
  const ClothModel m(in, ClothMaterial{});
  IntersectionCounter count(m.topology(), {}, {}, 0);
  ASSERT_EQ(count.self_pairs(m.initial_positions()).size(), 1u);
  std::vector<Vec3> v(9, Vec3::Zero());
  v[3] = Vec3(0.0, 8.0, 0.0);  // 8 cm up in the substep: through the lower triangle
  for (int i = 6; i < 9; ++i)
    v[i] = Vec3(0.0, -2.0, 0.0);  // 2 cm down through a 1 cm gap
  const OneStep s = one_step(m, v, 0.01);
  EXPECT_GT(s.stats.excluded, 0);
  EXPECT_EQ(s.stats.unresolved, 0);
  EXPECT_LT(s.stats.zone_rounds, ContactOptions{}.zone_rounds);
  EXPECT_GT(s.x1[3].y(), 0.02);  // the excluded vertex was not held back
  const Vec3 n = (s.x1[2] - s.x1[0]).cross(s.x1[1] - s.x1[0]).normalized();
  ASSERT_GT(n.y(), 0.9);
  for (int i = 6; i < 9; ++i)
    EXPECT_GT(n.dot(s.x1[i] - s.x1[0]), 0.0);  // the falling triangle stays above
  // The crossing is gone or unchanged, and no new one appeared.
  EXPECT_LE(count.self_pairs(s.x1).size(), 1u);
}

TEST(ContactHandler, ClothVertexInsideTheBodyEscapes) {
  // A body triangle facing +y (counter-clockwise seen from above: outside) and a cloth triangle
  // crossing it: vertex 0 is 3 mm behind it, the other two 5 mm in front.
  ClothMeshInput in;
  in.positions = {{0.3, -0.003, 0.3}, {0.6, 0.005, 0.3}, {0.3, 0.005, 0.6}};
  in.faces = {{0, 2, 1}};
  const ClothModel m(in, ClothMaterial{});
  const std::vector<Vec3> body = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}};
  const std::vector<Face> body_faces = {{0, 1, 2}};
  const std::vector<double> inv(3, 1.0 / m.mass()[0]);
  IntersectionCounter count(m.topology(), {}, body_faces, 3);
  const std::vector<std::pair<int, int>> crossing{{0, 0}};  // (cloth face, body face)
  ASSERT_EQ(count.body_pairs(m.initial_positions(), body), crossing);
  for (double step : {0.0, 2e-3}) {
    ContactOptions o;
    o.untangle_step = step;
    ContactHandler handler(m, o);
    std::vector<Vec3> x = m.initial_positions();
    const double h = 0.005;
    for (int k = 0; k < 5; ++k) {
      SubstepContext ctx;
      ctx.h = h;
      ctx.x0 = x;
      ctx.inverse_mass = inv;
      ctx.cloth = &m.topology();
      ctx.body_t0 = body;
      ctx.body_t1 = body;
      ctx.body_faces = &body_faces;
      handler.prepare(ctx);
      std::vector<Vec3> v(3, Vec3::Zero());
      (void)handler.respond(ctx, v);
      for (int i = 0; i < 3; ++i)
        x[i] += h * v[i];
    }
    if (step == 0.0) {
      // Nothing else undoes a crossing: it stays.
      EXPECT_EQ(count.body_pairs(x, body), crossing);
    } else {
      // 4 mm to go (3 mm depth + 1 mm thickness) at 2 mm per substep: out in two substeps, to
      // about the repulsion distance in front of the face, and no further.
      EXPECT_TRUE(count.body_pairs(x, body).empty());
      EXPECT_GT(x[0].y(), 0.0005);
      EXPECT_LT(x[0].y(), 0.002);
      EXPECT_NEAR(x[1].y(), 0.005, 1e-9);
    }
  }
}

TEST(ContactHandler, SqueezedStackIsResolvedByTheProjectionAlone) {
  // Three horizontal squares 1 cm apart; the bottom one rises and the top one falls 1.5 cm in
  // the substep, so both outer pairs cross the middle one. Pushing the middle sheet away from
  // one neighbour pushes it into the other: the impulses must be found together, and the
  // accumulated projection does that without falling back to impact zones.
  ClothMeshInput in;
  const std::array<double, 3> lo{0.0, 0.1, 0.2}, hi{1.0, 0.9, 0.8};
  for (int k = 0; k < 3; ++k) {
    const double y = 0.01 * k;
    in.positions.insert(
        in.positions.end(),
        {{lo[k], y, lo[k]}, {hi[k], y, lo[k]}, {hi[k], y, hi[k]}, {lo[k], y, hi[k]}});
    const int b = 4 * k;
    in.faces.push_back({b, b + 2, b + 1});
    in.faces.push_back({b, b + 3, b + 2});
  }
  const ClothModel m(in, ClothMaterial{});
  std::vector<Vec3> v(12, Vec3::Zero());
  for (int i = 0; i < 4; ++i) {
    v[i] = Vec3(0.0, 1.5, 0.0);
    v[8 + i] = Vec3(0.0, -1.5, 0.0);
  }
  const Vec3 p0 = total_momentum(m, v);
  const OneStep s = one_step(m, v, 0.01);
  EXPECT_GT(s.stats.ccd_hits, 0);
  EXPECT_EQ(s.stats.zone_rounds, 0);
  EXPECT_EQ(s.stats.unresolved, 0);
  SelfDetector d(m.topology().faces(), 12, to_matrix(m.initial_positions()));
  const DetectResult r = d.detect(to_matrix(m.initial_positions()), to_matrix(s.x1));
  EXPECT_TRUE(r.vf.empty());
  EXPECT_TRUE(r.ee.empty());
  // The sheets end in their order at their common centre, which lies on each sheet's diagonal
  // (their corners may tilt past each other outside the narrower sheets' footprint).
  std::array<double, 3> y{};
  for (int k = 0; k < 3; ++k)
    y[k] = 0.5 * (s.x1[4 * k].y() + s.x1[4 * k + 2].y());
  EXPECT_LT(y[0], y[1]);
  EXPECT_LT(y[1], y[2]);
  EXPECT_LT((total_momentum(m, s.v) - p0).norm(), 1e-12);
}

TEST(ContactHandler, AnchoredZoneFollowsTheBodyWhereItTouchesIt) {
  // A large cloth triangle at rest is held between two spike tips of a body that tilts about
  // the x axis: the tip below it at z = 0.2 rises 4 mm, the tip above it at z = -0.2 falls 4 mm.
  // Each tip touches the cloth's face far from the cloth's vertices, so the zone's rigid motion
  // must be fitted to the body's velocities at the tips. Fitted at the cloth vertices (each given
  // the tips' mean velocity) it stood still, and both tips went through the cloth.
  ClothMeshInput in;
  in.positions = {{0, 0, 0.5}, {0.45, 0, -0.5}, {-0.45, 0, -0.5}};
  in.faces = {{0, 2, 1}};
  const ClothModel m(in, ClothMaterial{});
  std::vector<Vec3> body;
  std::vector<Face> body_faces;
  for (const auto& [z, side] : {std::pair{0.2, -1.0}, {-0.2, 1.0}}) {
    const int b = static_cast<int>(body.size());
    const double y = 0.0015 * side, base = 0.05 * side;
    body.insert(body.end(),
                {{0, y, z}, {0.01, base, z}, {-0.005, base, z + 0.01}, {-0.005, base, z - 0.01}});
    body_faces.insert(body_faces.end(), {{b, b + 1, b + 2}, {b, b + 2, b + 3}, {b, b + 3, b + 1}});
  }
  const double angle = -0.02;  // about x: y' = y cos - z sin, z' = y sin + z cos
  std::vector<Vec3> body1;
  for (const Vec3& b : body)
    body1.emplace_back(b.x(), b.y() * std::cos(angle) - b.z() * std::sin(angle),
                       b.y() * std::sin(angle) + b.z() * std::cos(angle));
  ContactOptions opt;
  opt.ccd_iterations = 0;  // straight to the zones ...
  opt.full_passes = true;  // ... testing every pair in each round
  const OneStep s =
      one_step(m, std::vector<Vec3>(3, Vec3::Zero()), 0.01, body, &body_faces, body1, opt);
  EXPECT_GT(s.stats.zone_rounds, 0);
  EXPECT_EQ(s.stats.unresolved, 0);
  IntersectionCounter c(m.topology(), {}, body_faces, static_cast<int>(body.size()));
  EXPECT_TRUE(c.body_pairs(s.x1, body1).empty());
  // The cloth ends between the tips (its normal points up).
  const Vec3 n = (s.x1[1] - s.x1[0]).cross(s.x1[2] - s.x1[0]).normalized();
  ASSERT_GT(n.y(), 0.0);
  EXPECT_LT(n.dot(body1[0] - s.x1[0]), 0.0);
  EXPECT_GT(n.dot(body1[4] - s.x1[0]), 0.0);
}

// A cloth folded at a right angle (face A in the plane y = 0, face B in x = 0, sharing the z
// axis) held between spike tips 1.5 mm either side of each face at four points, while the body
// shears: each point moves by S p with S = [[0, s, 0], [s, 0, 0], [0, 0, 0]], 2-6 mm across the
// faces. The anchors span a volume and follow an affine field that no rigid motion matches.
struct FoldInShearingBody {
  ClothModel cloth;
  std::vector<Vec3> body, body1;
  std::vector<Face> faces;
  std::vector<std::pair<int, int>> sandwiches;  // (tip on the - side, tip on the + side)

  static ClothMeshInput fold() {
    ClothMeshInput in;
    in.positions = {{0, 0, 0.5}, {0, 0, -0.5}, {0.45, 0, 0}, {0, 0.45, 0}};
    in.faces = {{0, 1, 2}, {0, 3, 1}};
    return in;
  }

  explicit FoldInShearingBody(double s) : cloth(fold(), ClothMaterial{}) {
    const Vec3 y(0, 1, 0), x(1, 0, 0);
    for (const auto& [p, n] : {std::pair{Vec3(0.1, 0, 0.1), y},
                               {Vec3(0.3, 0, 0.1), y},
                               {Vec3(0, 0.1, -0.1), x},
                               {Vec3(0, 0.3, -0.1), x}}) {
      const Vec3 t1 = n.cross(Vec3(0, 0, 1)), t2 = n.cross(t1);
      std::array<int, 2> tips{};
      for (int k = 0; k < 2; ++k) {
        const double side = k == 0 ? -1.0 : 1.0;
        const int b = static_cast<int>(body.size());
        tips[k] = b;
        const Vec3 base = p + 0.05 * side * n;
        body.insert(body.end(), {p + 0.0015 * side * n, base + 0.01 * t1,
                                 base - 0.005 * t1 + 0.01 * t2, base - 0.005 * t1 - 0.01 * t2});
        faces.insert(faces.end(), {{b, b + 1, b + 2}, {b, b + 2, b + 3}, {b, b + 3, b + 1}});
      }
      sandwiches.emplace_back(tips[0], tips[1]);
    }
    for (const Vec3& b : body)
      body1.push_back(b + s * Vec3(b.y(), b.x(), 0.0));
  }

  // Each sandwich's tips end on either side of the face they hold.
  [[nodiscard]] bool held(const std::vector<Vec3>& x1) const {
    const std::array<std::array<int, 3>, 2> f{{{0, 1, 2}, {0, 3, 1}}};
    for (std::size_t q = 0; q < sandwiches.size(); ++q) {
      const auto& t = f[q < 2 ? 0 : 1];
      const Vec3 n = (x1[t[1]] - x1[t[0]]).cross(x1[t[2]] - x1[t[0]]);
      const double below = n.dot(body1[sandwiches[q].first] - x1[t[0]]);
      const double above = n.dot(body1[sandwiches[q].second] - x1[t[0]]);
      if (!(below * above < 0.0)) return false;
    }
    return true;
  }
};

TEST(ContactHandler, AnchoredZoneFollowsABodyThatShears) {
  const FoldInShearingBody scene(0.02);
  ContactOptions opt;
  opt.ccd_iterations = 0;  // straight to the zones ...
  opt.full_passes = true;  // ... testing every pair in each round
  const auto run = [&](bool affine) {
    opt.affine_zones = affine;
    return one_step(scene.cloth, std::vector<Vec3>(4, Vec3::Zero()), 0.01, scene.body, &scene.faces,
                    scene.body1, opt);
  };
  IntersectionCounter c(scene.cloth.topology(), {}, scene.faces,
                        static_cast<int>(scene.body.size()));
  const OneStep affine = run(true);
  EXPECT_GT(affine.stats.zone_rounds, 0);
  EXPECT_EQ(affine.stats.unresolved, 0);
  EXPECT_TRUE(c.body_pairs(affine.x1, scene.body1).empty());
  EXPECT_TRUE(scene.held(affine.x1));
  // The rigid zone cannot follow it: hits are left and tips go through.
  const OneStep rigid = run(false);
  EXPECT_GT(rigid.stats.unresolved, 0);
  EXPECT_FALSE(scene.held(rigid.x1));
}

}  // namespace
}  // namespace clothcd::sim
