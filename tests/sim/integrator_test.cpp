// Implicit Euler + PCG: closed-form free fall, momentum, pins, a hanging cloth, determinism.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <random>
#include <span>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/sim/collision.hpp"
#include "clothcd/sim/integrator.hpp"
#include "grid.hpp"
#include "hash.hpp"

namespace clothcd::sim {
namespace {

using test::grid_cloth;
using test::random_vec;

Vec3 momentum(const ClothModel& m, const std::vector<Vec3>& v) {
  Vec3 p = Vec3::Zero();
  for (int i = 0; i < m.num_vertices(); ++i)
    p += m.mass()[i] * v[i];
  return p;
}

double total_mass(const ClothModel& m) {
  double s = 0.0;
  for (double x : m.mass())
    s += x;
  return s;
}

TEST(ClothModel, LumpedMassIsAreaDensityTimesArea) {
  const ClothModel m(grid_cloth(8, 5, 0.8, 0.5), ClothMaterial{});
  EXPECT_NEAR(total_mass(m), 0.15 * 0.8 * 0.5, 1e-12);
  EXPECT_EQ(m.num_slivers(), 0);
  EXPECT_GT(m.hinges().size(), 0u);
}

TEST(Integrator, FreeFallMatchesImplicitEulerClosedForm) {
  for (int seed = 0; seed < 4; ++seed) {
    std::mt19937_64 rng(seed);
    const ClothModel m(grid_cloth(6, 6, 0.3, 0.3, 1.0), ClothMaterial{});
    SolverOptions opt;
    opt.gravity = random_vec(rng, 10.0);
    opt.pcg_tolerance = 1e-12;
    ClothSolver solver(m, opt);
    ClothState s = solver.initial_state();
    const Vec3 v0 = random_vec(rng, 1.0);
    for (auto& v : s.v)
      v = v0;
    const double h = 0.01;
    const int steps = 20;
    for (int k = 0; k < steps; ++k)
      solver.step(s, h);
    // v_n = v0 + n h g, x_n = x0 + n h v0 + h^2 g n (n + 1) / 2: a rigid translation keeps the
    // membrane at rest, so only gravity acts.
    const Vec3 v_expected = v0 + steps * h * opt.gravity;
    const Vec3 dx = steps * h * v0 + h * h * opt.gravity * steps * (steps + 1) / 2.0;
    for (int i = 0; i < m.num_vertices(); ++i) {
      EXPECT_LE((s.v[i] - v_expected).norm(), 1e-9) << "seed " << seed << " vertex " << i;
      EXPECT_LE((s.x[i] - (m.initial_positions()[i] + dx)).norm(), 1e-9) << "seed " << seed;
    }
  }
}

TEST(Integrator, LinearMomentumConservedWithoutGravity) {
  for (int seed = 0; seed < 4; ++seed) {
    std::mt19937_64 rng(100 + seed);
    ClothMeshInput in = grid_cloth(8, 8, 0.4, 0.4);
    in.stitches.push_back({0, 70, 71, 0.3});  // a stitch term too
    const ClothModel m(in, ClothMaterial{});
    SolverOptions opt;
    opt.gravity = Vec3::Zero();
    opt.pcg_tolerance = 1e-11;
    opt.pcg_max_iterations = 5000;
    ClothSolver solver(m, opt);
    ClothState s = solver.initial_state();
    for (auto& x : s.x)
      x += random_vec(rng, 0.01);  // stressed start
    for (auto& v : s.v)
      v = random_vec(rng, 0.5);
    const Vec3 p0 = momentum(m, s.v);
    for (int k = 0; k < 10; ++k) {
      solver.step(s, 0.01);
      EXPECT_LE((momentum(m, s.v) - p0).norm(), 1e-8 * total_mass(m)) << "seed " << seed;
    }
  }
}

TEST(Integrator, GravityChangesMomentumByMgh) {
  const ClothModel m(grid_cloth(8, 8, 0.4, 0.4), ClothMaterial{});
  SolverOptions opt;
  opt.pcg_tolerance = 1e-11;
  opt.pcg_max_iterations = 5000;
  ClothSolver solver(m, opt);
  ClothState s = solver.initial_state();
  std::mt19937_64 rng(5);
  for (auto& v : s.v)
    v = random_vec(rng, 0.5);
  for (int k = 0; k < 5; ++k) {
    const Vec3 p = momentum(m, s.v);
    solver.step(s, 0.01);
    EXPECT_LE((momentum(m, s.v) - p - total_mass(m) * 0.01 * opt.gravity).norm(),
              1e-9 * total_mass(m));
  }
}

TEST(Integrator, FastStepsSolveToTheFastToleranceWhenOneIsSet) {
  const ClothModel m(grid_cloth(10, 10, 0.4, 0.4), ClothMaterial{});
  SolverOptions opt;
  opt.pcg_tolerance = 1e-8;
  opt.fast_pcg_tolerance = 1e-3;
  opt.pcg_max_iterations = 5000;
  ClothSolver solver(m, opt);
  ClothState start = solver.initial_state();
  std::mt19937_64 rng(7);
  for (auto& v : start.v)
    v = random_vec(rng, 0.5);
  ClothState plain = start, fast = start;
  const StepStats sp = solver.step(plain, 0.01);
  const StepStats sf = solver.step(fast, 0.01, true);
  EXPECT_EQ(sp.pcg_tolerance, 1e-8);
  EXPECT_EQ(sf.pcg_tolerance, 1e-3);
  EXPECT_LT(sf.pcg_iterations, sp.pcg_iterations);
  EXPECT_NE(plain.x, fast.x);
  // Unset, a fast step is the plain one, bit for bit.
  opt.fast_pcg_tolerance = 0.0;
  ClothSolver unset(m, opt);
  ClothState a = start, b = start;
  (void)unset.step(a, 0.01);
  const StepStats sb = unset.step(b, 0.01, true);
  EXPECT_EQ(sb.pcg_tolerance, 1e-8);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.v, b.v);
  EXPECT_EQ(plain.x, a.x);
}

ClothState hang(ClothSolver& solver, const ClothModel& m, int nx, int steps,
                std::vector<double>* kinetic = nullptr, double* stretch = nullptr) {
  ClothState s = solver.initial_state();
  PinGroup corners;
  corners.vertices = {0, nx};
  solver.add_pins(corners, s.x);
  for (int k = 0; k < steps; ++k) {
    const StepStats st = solver.step(s, 0.01);
    if (kinetic) kinetic->push_back(solver.kinetic_energy(s.v));
    if (stretch) *stretch = std::max(*stretch, st.max_stretch);
  }
  (void)m;
  return s;
}

TEST(Integrator, HangingClothSettles) {
  const int nx = 10;
  const ClothModel m(grid_cloth(nx, nx, 0.4, 0.4, 1.0), ClothMaterial{});
  ClothSolver solver(m, SolverOptions{});
  std::vector<double> ke;
  double stretch = 0.0;
  const ClothState s = hang(solver, m, nx, 400, &ke, &stretch);
  for (const Vec3& x : s.x)
    ASSERT_TRUE(x.allFinite());
  // Pins hold exactly.
  EXPECT_EQ(s.x[0], m.initial_positions()[0]);
  EXPECT_EQ(s.x[nx], m.initial_positions()[nx]);
  // Kinetic energy decays: the peak of each second is below the previous second's.
  std::vector<double> window_peak;
  for (std::size_t k = 0; k < ke.size(); k += 100) {
    window_peak.push_back(*std::max_element(ke.begin() + k, ke.begin() + k + 100));
  }
  for (std::size_t w = 1; w < window_peak.size(); ++w) {
    EXPECT_LT(window_peak[w], window_peak[w - 1]) << "second " << w;
  }
  EXPECT_LT(window_peak.back(), 0.2 * window_peak.front());
  EXPECT_LT(stretch, 0.3);
  EXPECT_LT(solver.max_stretch(s.x), 0.3);
  // It hangs below the pins.
  EXPECT_LT(s.x[(nx + 1) * nx + nx / 2].y(), 1.0 - 0.2);
}

TEST(Integrator, CoarseCorrectionHangsTheClothWhereBlockJacobiDoes) {
  // The two-level preconditioner changes the solve's path, not its answer: after 100 steps of
  // the hanging cloth the two runs agree to a small fraction of how far the cloth fell.
  const int nx = 20;
  const ClothModel m(grid_cloth(nx, nx, 0.4, 0.4, 1.0), ClothMaterial{});
  SolverOptions tight;
  tight.pcg_tolerance = 1e-8;
  SolverOptions coarse = tight;
  coarse.coarse_aggregate = 16;
  ClothSolver a(m, tight), b(m, coarse);
  const ClothState sa = hang(a, m, nx, 100), sb = hang(b, m, nx, 100);
  const int mid = (nx + 1) * nx + nx / 2;
  const double fall = 1.0 - sa.x[mid].y();
  ASSERT_GT(fall, 0.1);
  for (int i = 0; i < m.num_vertices(); ++i)
    EXPECT_LE((sa.x[i] - sb.x[i]).norm(), 1e-4 * fall) << "vertex " << i;
  SolverOptions one = tight;
  one.coarse_aggregate = 1;
  EXPECT_THROW({ ClothSolver bad(m, one); }, InputError);
}

TEST(Integrator, RotatingHandlesAreFollowedExactly) {
  const int nx = 10;
  const ClothModel m(grid_cloth(nx, nx, 0.3, 0.3), ClothMaterial{});
  SolverOptions opt;
  opt.gravity = Vec3::Zero();
  ClothSolver solver(m, opt);
  ClothState s = solver.initial_state();
  PinGroup left, right;
  for (int j = 0; j <= nx; ++j) {
    left.vertices.push_back(j * (nx + 1));
    right.vertices.push_back(j * (nx + 1) + nx);
  }
  left.center = Vec3(0, 0, 0.15);
  left.axis = Vec3::UnitX();
  left.angular_velocity = 1.0;
  right.center = Vec3(0.3, 0, 0.15);
  right.axis = Vec3::UnitX();
  right.angular_velocity = -1.0;
  right.velocity = Vec3(-0.005, 0, 0);
  solver.add_pins(left, s.x);
  solver.add_pins(right, s.x);
  for (int k = 0; k < 20; ++k)
    solver.step(s, 0.01);
  const Eigen::AngleAxisd rot(-0.2, Vec3::UnitX());
  const int v = 3 * (nx + 1) + nx;
  const Vec3 target =
      right.center + right.velocity * 0.2 + rot * (m.initial_positions()[v] - right.center);
  EXPECT_LE((s.x[v] - target).norm(), 1e-12);
  for (const Vec3& x : s.x)
    ASSERT_TRUE(x.allFinite());
}

std::uint64_t run_hash(int threads) {
  const int nx = 24;
  const ClothModel m(grid_cloth(nx, nx, 0.4, 0.4, 1.0), ClothMaterial{});
  ClothSolver solver(m, SolverOptions{});
  ClothState s;
  tbb::task_arena arena(threads);
  arena.execute([&] { s = hang(solver, m, nx, 20); });
  return test::hash_positions(s.x) ^ (test::hash_positions(s.v) * 31);
}

TEST(Integrator, BitwiseDeterministicAcrossRunsAndThreadCounts) {
  const std::uint64_t a = run_hash(2);
  EXPECT_EQ(a, run_hash(2));
  EXPECT_EQ(a, run_hash(1));
}

// A handler that leaves `unresolved` hits in every substep longer than `longest` and records the
// substeps it was asked to respond to.
class UnresolvedAboveLength : public CollisionHandler {
 public:
  UnresolvedAboveLength(double longest, long long unresolved)
      : longest_(longest), unresolved_(unresolved) {}
  void prepare(const SubstepContext&) override {}
  CollisionStats respond(const SubstepContext& ctx, std::span<Vec3>) override {
    lengths.push_back(ctx.h);
    CollisionStats st;
    if (ctx.h > longest_) st.unresolved = unresolved_;
    return st;
  }
  std::vector<double> lengths;

 private:
  double longest_;
  long long unresolved_;
};

TEST(Integrator, SubstepWithUnresolvedHitsIsHalvedUntilResolved) {
  const ClothModel m(grid_cloth(4, 4, 0.2, 0.2, 1.0), ClothMaterial{});
  SolverOptions opt;
  opt.pcg_tolerance = 1e-12;
  const double h = 0.008;
  // Halving on: 8 ms fails, both 4 ms halves fail, the four 2 ms quarters pass.
  ClothSolver halving(m, opt);
  UnresolvedAboveLength handler(0.0025, 7);
  halving.set_collision_handler(&handler);
  ClothState s = halving.initial_state();
  const StepStats st = halving.step(s, h);
  EXPECT_EQ(handler.lengths, (std::vector<double>{h, h / 2, h / 4, h / 4, h / 2, h / 4, h / 4}));
  EXPECT_EQ(st.halvings, 3);
  EXPECT_EQ(st.solves, 7);
  EXPECT_EQ(st.collision.unresolved, 0);  // the failed attempts' hits are not counted
  EXPECT_DOUBLE_EQ(s.time, h);
  // The state is that of four plain quarter steps: failed attempts leave it untouched.
  ClothSolver plain(m, opt);
  ClothState q = plain.initial_state();
  for (int k = 0; k < 4; ++k)
    plain.step(q, h / 4);
  for (int i = 0; i < m.num_vertices(); ++i) {
    EXPECT_EQ(s.x[i], q.x[i]) << i;
    EXPECT_EQ(s.v[i], q.v[i]) << i;
  }
}

TEST(Integrator, UnresolvedHitsAreAcceptedAtTheLastHalvingOrWhenHalvingIsOff) {
  const ClothModel m(grid_cloth(4, 4, 0.2, 0.2, 1.0), ClothMaterial{});
  SolverOptions opt;
  opt.max_halvings = 1;
  {
    // Never resolved: the two halves are the last chance and keep their hits.
    ClothSolver solver(m, opt);
    UnresolvedAboveLength handler(0.0, 5);
    solver.set_collision_handler(&handler);
    ClothState s = solver.initial_state();
    const StepStats st = solver.step(s, 0.01);
    EXPECT_EQ(handler.lengths, (std::vector<double>{0.01, 0.005, 0.005}));
    EXPECT_EQ(st.halvings, 1);
    EXPECT_EQ(st.collision.unresolved, 10);
    EXPECT_DOUBLE_EQ(s.time, 0.01);
  }
  {
    opt.halve_unresolved = false;
    ClothSolver solver(m, opt);
    UnresolvedAboveLength handler(0.0, 5);
    solver.set_collision_handler(&handler);
    ClothState s = solver.initial_state();
    const StepStats st = solver.step(s, 0.01);
    EXPECT_EQ(handler.lengths, std::vector<double>{0.01});
    EXPECT_EQ(st.halvings, 0);
    EXPECT_EQ(st.collision.unresolved, 5);
  }
}

// A handler that asks the solve to keep fixed contact constraints and couplings and changes
// nothing after it.
class FixedConstraints : public CollisionHandler {
 public:
  explicit FixedConstraints(std::vector<ContactConstraint> c, std::vector<ContactCoupling> k = {})
      : c_(std::move(c)), k_(std::move(k)) {}
  void prepare(const SubstepContext&) override {}
  void contact_constraints(std::vector<ContactConstraint>& out) const override { out = c_; }
  void contact_couplings(std::vector<ContactCoupling>& out) const override { out = k_; }
  CollisionStats respond(const SubstepContext&, std::span<Vec3>) override { return {}; }

 private:
  std::vector<ContactConstraint> c_;
  std::vector<ContactCoupling> k_;
};

// One step of h from rest under the given constraints and couplings (none: the free step), PCG
// to 1e-12.
ClothState step_held(const ClothModel& m, std::vector<ContactConstraint> constraints, double h,
                     StepStats* stats = nullptr, std::vector<ContactCoupling> couplings = {}) {
  SolverOptions opt;
  opt.pcg_tolerance = 1e-12;
  ClothSolver solver(m, opt);
  FixedConstraints handler(std::move(constraints), std::move(couplings));
  solver.set_collision_handler(&handler);
  ClothState s = solver.initial_state();
  const StepStats st = solver.step(s, h);
  if (stats != nullptr) *stats = st;
  return s;
}

TEST(Integrator, ContactConstraintHoldsItsVertexAndThroughItTheClothAroundIt) {
  // A horizontal cloth under gravity resting on one point in its middle (vertex 12 of 5 x 5).
  // The normal is given unnormalized, and a second constraint on the same vertex is ignored.
  const ClothModel m(grid_cloth(4, 4, 0.04, 0.04, 1.0), ClothMaterial{});
  const double h = 0.002;
  const ClothState f = step_held(m, {}, h);
  const ClothState s = step_held(m, {{12, Vec3(0, 2, 0), 0.01}, {12, Vec3(1, 0, 0), 5.0}}, h);
  EXPECT_NEAR(s.v[12].y(), 0.01, 1e-12);  // the prescribed normal velocity, exactly
  EXPECT_NEAR(s.v[12].x(), 0.0, 1e-12);
  EXPECT_NEAR(s.v[12].z(), 0.0, 1e-12);
  // Its neighbours fall slower than the free cloth, which falls as one piece.
  for (int i : {7, 11, 13, 17}) {
    EXPECT_NEAR(f.v[i].y(), -9.81 * h, 1e-9);
    EXPECT_GT(s.v[i].y(), f.v[i].y() + 1e-3) << i;
  }
}

TEST(Integrator, ContactConstraintThatWouldPullItsVertexIsLetGo) {
  // The contact is above the cloth (normal pointing down) and gravity pulls the cloth away from
  // it: holding the vertex would be adhesion, so the step is the free one, in one attempt.
  const ClothModel m(grid_cloth(4, 4, 0.04, 0.04, 1.0), ClothMaterial{});
  const double h = 0.002;
  const ClothState f = step_held(m, {}, h);
  StepStats st;
  const ClothState s = step_held(m, {{12, Vec3(0, -1, 0), 0.0}}, h, &st);
  for (int i = 0; i < m.num_vertices(); ++i)
    EXPECT_LE((s.v[i] - f.v[i]).norm(), 1e-9) << i;
  EXPECT_EQ(st.solves, 1);
}

TEST(Integrator, FirstSolveStoppedAtTheReleaseToleranceEndsWhereTheCompleteOneDoes) {
  // A cloth held at its middle vertex (a constraint that holds), with and without a second one at
  // a corner that is let go (it would pull the cloth up). Stopping the first solve at
  // release_tolerance lets go the same constraint and still ends at pcg_tolerance, at the
  // complete first solve's result, whether a constraint was let go or not.
  const ClothModel m(grid_cloth(6, 6, 0.06, 0.06, 1.0), ClothMaterial{});
  for (const bool corner : {false, true}) {
    std::vector<ContactConstraint> c = {{24, Vec3(0, 1, 0), 0.0}};
    if (corner) c.push_back({0, Vec3(0, -1, 0), 0.0});
    auto run = [&](double release_tolerance, StepStats& st) {
      SolverOptions opt;
      opt.pcg_tolerance = 1e-11;
      opt.release_tolerance = release_tolerance;
      ClothSolver solver(m, opt);
      FixedConstraints handler(c);
      solver.set_collision_handler(&handler);
      ClothState s = solver.initial_state();
      st = solver.step(s, 0.002);
      return s;
    };
    StepStats loose, complete;
    const ClothState a = run(1e-2, loose), b = run(1e-11, complete);
    EXPECT_TRUE(loose.converged);
    EXPECT_TRUE(complete.converged);
    EXPECT_EQ(loose.solves, 1);  // one attempt: no halving
    EXPECT_NEAR(a.v[24].y(), 0.0, 1e-12);
    if (corner) {
      EXPECT_LT(a.v[0].y(), -1e-3);  // let go: it falls
    }
    double scale = 0.0;
    for (int i = 0; i < m.num_vertices(); ++i)
      scale = std::max(scale, b.v[i].norm());
    ASSERT_GT(scale, 0.0);
    for (int i = 0; i < m.num_vertices(); ++i)
      EXPECT_LE((a.v[i] - b.v[i]).norm(), 1e-8 * scale) << "corner " << corner << " vertex " << i;
  }
}

TEST(Integrator, ContactConstraintsOnNoVertexOrAlongNoDirectionAreIgnored) {
  const ClothModel m(grid_cloth(2, 2, 0.04, 0.04, 1.0), ClothMaterial{});
  const ClothState f = step_held(m, {}, 0.002);
  const ClothState s = step_held(m,
                                 {{-1, Vec3(0, 1, 0), 0.0},
                                  {m.num_vertices(), Vec3(0, 1, 0), 0.0},
                                  {4, Vec3::Zero(), 0.0},
                                  {4, Vec3(0, 1, 0), NAN}},
                                 0.002);
  for (int i = 0; i < m.num_vertices(); ++i)
    EXPECT_EQ(s.v[i], f.v[i]) << i;
}

// Two separate horizontal triangles: the lower (0, 1, 2) at y = 0, the upper (3, 4, 5) 0.5 mm
// above it and inside it in x and z.
ClothMeshInput two_layers() {
  ClothMeshInput in;
  in.positions = {{0, 0, 0},          {0.1, 0, 0},        {0, 0, 0.1},
                  {0.02, 5e-4, 0.02}, {0.06, 5e-4, 0.02}, {0.02, 5e-4, 0.06}};
  in.faces = {{0, 2, 1}, {3, 5, 4}};
  return in;
}

// Upper vertex u of two_layers() against the lower face: weights of its point below, normal +y.
ContactCoupling upper_on_lower(const ClothMeshInput& in, int u, double target) {
  const Vec3& p = in.positions[u];
  const double w1 = p.x() / 0.1, w2 = p.z() / 0.1;
  ContactCoupling c;
  c.vertex = {u, 0, 1, 2};
  c.c = {1.0, -(1.0 - w1 - w2), -w1, -w2};
  c.n = Vec3(0, 1, 0);
  c.normal_velocity = target;
  return c;
}

// The lower layer held still along y by constraints.
std::vector<ContactConstraint> lower_held() {
  return {{0, Vec3(0, 1, 0), 0.0}, {1, Vec3(0, 1, 0), 0.0}, {2, Vec3(0, 1, 0), 0.0}};
}

TEST(Integrator, ContactCouplingKeepsALayerFromFallingOntoTheOneBelow) {
  const ClothMeshInput in = two_layers();
  const ClothModel m(in, ClothMaterial{});
  const double h = 0.002, target = 0.01;
  const ClothState f = step_held(m, lower_held(), h);
  std::vector<ContactCoupling> k;
  for (int u : {3, 4, 5})
    k.push_back(upper_on_lower(in, u, target));
  StepStats st;
  const ClothState s = step_held(m, lower_held(), h, &st, k);
  for (int u : {3, 4, 5}) {
    EXPECT_NEAR(f.v[u].y(), -9.81 * h, 1e-9);  // free: the upper layer falls
    // Coupled: it leaves at most 2% of the free approach beyond the target (the penalty is 100
    // effective masses), and it is not pushed apart faster than asked either.
    const double free_gap = f.v[u].y() - target, gap = s.v[u].y() - target;
    EXPECT_LE(gap, 0.0) << u;
    EXPECT_GE(gap, 0.02 * free_gap) << u;
  }
  for (int i : {0, 1, 2})
    EXPECT_NEAR(s.v[i].y(), 0.0, 1e-12);  // the held layer stays held
  EXPECT_EQ(st.solves, 1);
}

TEST(Integrator, ContactCouplingFollowsTheBodyItTouches) {
  // The upper triangle against a body point under each vertex that rises at 0.1 m/s: all body
  // weights, so the whole relative velocity of the other side is body_velocity.
  const ClothMeshInput in = two_layers();
  const ClothModel m(in, ClothMaterial{});
  const double h = 0.002, target = 0.01;
  std::vector<ContactCoupling> k;
  for (int u : {3, 4, 5}) {
    ContactCoupling c;
    c.vertex = {u, -1, -1, -1};
    c.c = {1.0, -1.0, 0.0, 0.0};
    c.n = Vec3(0, 1, 0);
    c.body_velocity = -1.0 * 0.1;  // c_1 n . v_body
    c.normal_velocity = target;
    k.push_back(c);
  }
  const ClothState s = step_held(m, lower_held(), h, nullptr, k);
  for (int u : {3, 4, 5}) {
    const double free_gap = -9.81 * h - 0.1 - target, gap = s.v[u].y() - 0.1 - target;
    EXPECT_LE(gap, 0.0) << u;
    EXPECT_GE(gap, 0.02 * free_gap) << u;
  }
}

TEST(Integrator, ContactCouplingThatWouldHoldItsPairTogetherIsLetGo) {
  // The same pair seen with the normal reversed: gravity separates it, so the coupling would be
  // adhesive. The step is the free one, redone within the one attempt.
  const ClothMeshInput in = two_layers();
  const ClothModel m(in, ClothMaterial{});
  const double h = 0.002;
  const ClothState f = step_held(m, lower_held(), h);
  std::vector<ContactCoupling> k;
  for (int u : {3, 4, 5}) {
    ContactCoupling c = upper_on_lower(in, u, 0.0);
    c.n = -c.n;
    k.push_back(c);
  }
  StepStats st;
  const ClothState s = step_held(m, lower_held(), h, &st, k);
  for (int i = 0; i < m.num_vertices(); ++i)
    EXPECT_LE((s.v[i] - f.v[i]).norm(), 1e-9) << i;
  EXPECT_EQ(st.solves, 1);
}

TEST(Integrator, ContactCouplingsOnNoVertexOrAlongNoDirectionAreIgnored) {
  const ClothMeshInput in = two_layers();
  const ClothModel m(in, ClothMaterial{});
  const ClothState f = step_held(m, lower_held(), 0.002);
  ContactCoupling out_of_range = upper_on_lower(in, 3, 0.01);
  out_of_range.vertex[1] = m.num_vertices();
  ContactCoupling no_normal = upper_on_lower(in, 3, 0.01);
  no_normal.n = Vec3::Zero();
  ContactCoupling nan_target = upper_on_lower(in, 3, NAN);
  ContactCoupling body_only = upper_on_lower(in, 3, 0.01);
  body_only.vertex = {-1, -1, -1, -1};
  const ClothState s =
      step_held(m, lower_held(), 0.002, nullptr, {out_of_range, no_normal, nan_target, body_only});
  for (int i = 0; i < m.num_vertices(); ++i)
    EXPECT_EQ(s.v[i], f.v[i]) << i;
}

}  // namespace
}  // namespace clothcd::sim
