// Collision scenes through Simulation: a cloth dropped on a sphere, a strip folding onto itself on
// a floor (zero intersections in every frame), determinism with collisions. Labelled slow: a few
// seconds in Release, much more under sanitizers.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <nlohmann/json.hpp>

#include "clothcd/sim/simulation.hpp"
#include "hash.hpp"
#include "sim/scene_json.hpp"

namespace clothcd::sim {
namespace {

using nlohmann::json;

json sphere_scene(int frames, int res) {
  json j = json::parse(R"({
    "name": "small-sphere-drop", "frame_dt": 0.04,
    "cloth": {"grid": {"origin": [-0.3, 0.33, -0.3], "u": [0.6, 0, 0], "v": [0, 0, 0.6]}},
    "material": {"friction": 0.4},
    "substeps": {"cloth_displacement": 0.004},
    "body": {"type": "sphere", "center": [0, 0, 0], "radius": 0.25, "subdivisions": 2,
             "spin_axis": [0, 1, 0], "spin_deg_per_s": 180, "spin_start": 0.3},
    "collisions": {"self": true, "body": true, "thickness": 0.001}
  })");
  j["frames"] = frames;
  j["cloth"]["grid"]["resolution"] = {res, res};
  return j;
}

// Distance from the centre to the nearest face plane of a convex body mesh around it.
double inradius(Body& body, const Vec3& center) {
  std::vector<Vec3> b;
  body.positions_at(0.0, b);
  double r = 1e300;
  for (const Face& f : body.faces()) {
    const Vec3 n = (b[f[1]] - b[f[0]]).cross(b[f[2]] - b[f[0]]).normalized();
    r = std::min(r, std::abs(n.dot(b[f[0]] - center)));
  }
  return r;
}

TEST(Simulation, ClothDroppedOnSphereStaysOutsideAndIntersectionFree) {
  Simulation sim(parse_scene(sphere_scene(14, 14), "small.json"));
  const double r_in = inradius(*sim.scene().body, Vec3::Zero());
  const IntersectionCount c0 = sim.count_intersections();
  EXPECT_EQ(c0.self, 0);
  EXPECT_EQ(c0.body, 0);
  long long contacts = 0;
  for (int f = 0; f < 14; ++f) {
    const FrameStats fs = sim.advance_frame();
    ASSERT_TRUE(fs.finite) << "frame " << fs.frame;
    EXPECT_EQ(fs.self_intersections, 0) << "frame " << fs.frame;
    EXPECT_EQ(fs.body_intersections, 0) << "frame " << fs.frame;
    EXPECT_EQ(fs.collision.unresolved, 0) << "frame " << fs.frame;
    contacts += fs.collision.proximity_pairs;
    for (const Vec3& x : sim.state().x)
      ASSERT_GT(x.norm(), r_in) << "a vertex is inside the sphere at frame " << fs.frame;
  }
  EXPECT_GT(contacts, 0);
  // It draped: the corners hang well below the top of the sphere.
  double lowest = 1e300;
  for (const Vec3& x : sim.state().x)
    lowest = std::min(lowest, x.y());
  EXPECT_LT(lowest, 0.15);
}

// A static floor (two large triangles at y = 0).
class Floor final : public Body {
 public:
  void positions_at(double, std::vector<Vec3>& out) override {
    out = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  }
  [[nodiscard]] const std::vector<Face>& faces() const override { return faces_; }
  [[nodiscard]] double max_displacement(double, double) override { return 0.0; }
  [[nodiscard]] int num_vertices() const override { return 4; }

 private:
  std::vector<Face> faces_{{0, 2, 1}, {0, 3, 2}};
};

// A leaning vertical strip that falls on the floor and piles up on itself (many CCD passes per
// substep).
Scene folding_strip(bool full_passes) {
  json j = json::parse(R"({
    "name": "fold", "frames": 20, "frame_dt": 0.04,
    "cloth": {"grid": {"origin": [0, 0.01, 0], "u": [0.05, 0, 0], "v": [0.2, 0.2, 0.0],
                       "resolution": [4, 30]}},
    "material": {"friction": 0.3},
    "substeps": {"cloth_displacement": 0.004},
    "collisions": {"self": true, "body": true, "thickness": 0.001}
  })");
  j["collisions"]["full_passes"] = full_passes;
  Scene s = parse_scene(j, "fold.json");
  s.body = std::make_unique<Floor>();
  return s;
}

TEST(Simulation, StripFoldingOntoItselfStaysIntersectionFree) {
  Simulation sim(folding_strip(false));
  long long self_contacts = 0;
  for (int f = 0; f < 20; ++f) {
    const FrameStats fs = sim.advance_frame();
    ASSERT_TRUE(fs.finite);
    EXPECT_EQ(fs.self_intersections, 0) << "frame " << fs.frame;
    EXPECT_EQ(fs.body_intersections, 0) << "frame " << fs.frame;
    self_contacts += fs.collision.proximity_pairs;
    for (const Vec3& x : sim.state().x)
      ASSERT_GT(x.y(), 0.0) << "below the floor at frame " << fs.frame;
  }
  EXPECT_GT(self_contacts, 0);
  // It piled up: the top end came down to the floor.
  double highest = -1e300;
  for (const Vec3& x : sim.state().x)
    highest = std::max(highest, x.y());
  EXPECT_LT(highest, 0.12);  // the top started at 0.21 m
}

TEST(Simulation, ScopedCcdPassesGiveWhatFullPassesGive) {
  // Passes after the first test only pairs whose motion changed (or that just hit): the same
  // hits, so bitwise the same frames, as testing every pair in every pass.
  Simulation scoped(folding_strip(false));
  Simulation full(folding_strip(true));
  int substeps = 0, passes = 0;
  for (int f = 0; f < 12; ++f) {
    const FrameStats a = scoped.advance_frame();
    const FrameStats b = full.advance_frame();
    ASSERT_EQ(a.collision.ccd_hits, b.collision.ccd_hits) << "frame " << a.frame;
    ASSERT_EQ(a.collision.ccd_passes, b.collision.ccd_passes) << "frame " << a.frame;
    ASSERT_EQ(test::hash_positions(scoped.state().x), test::hash_positions(full.state().x))
        << "frame " << a.frame;
    substeps += a.substeps;
    passes += a.collision.ccd_passes;
  }
  EXPECT_GT(passes, substeps);  // later passes ran
}

std::uint64_t run_hash(int threads) {
  Simulation sim(parse_scene(sphere_scene(8, 10), "small.json"));
  tbb::task_arena arena(threads);
  arena.execute([&] {
    for (int f = 0; f < 8; ++f)
      (void)sim.advance_frame();
  });
  return test::hash_positions(sim.state().x) ^ (test::hash_positions(sim.state().v) * 31);
}

TEST(Simulation, CollisionsAreBitwiseDeterministic) {
  const std::uint64_t a = run_hash(2);
  EXPECT_EQ(a, run_hash(2));
  EXPECT_EQ(a, run_hash(1));
}

}  // namespace
}  // namespace clothcd::sim
