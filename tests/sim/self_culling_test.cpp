// The self CCD's culling and cone policy change what the detector costs, never the motion: a
// sheet pinned along one edge and swinging onto a sphere (self and body contact) gives the same
// bytes in every frame with no culling and with the sound culling under each cone policy; the
// per-frame detector figures follow the settings and do not depend on the thread count. The
// detectors' traversal front changes nothing either.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "clothcd/sim/simulation.hpp"
#include "sim/scene_json.hpp"

namespace clothcd::sim {
namespace {

constexpr int kFrames = 4;

Scene swinging_sheet(const std::string& culling, const std::string& policy,
                     int cull_min_triangles = 16, bool reuse_front = false) {
  nlohmann::json j = nlohmann::json::parse(R"({"name": "swing", "frames": 4, "frame_dt": 0.04,
    "cloth": {"grid": {"origin": [-0.3, 0.22, -0.3], "u": [0.6, 0, 0], "v": [0, 0, 0.6],
                       "resolution": [24, 24]}},
    "body": {"type": "sphere", "center": [0, 0, 0], "radius": 0.2, "subdivisions": 2},
    "collisions": {"self": true, "body": true, "thickness": 0.002},
    "pins": [{"grid_edge": "u0"}]})");
  j["collisions"]["culling"] = culling;
  j["collisions"]["cone_policy"] = policy;
  j["collisions"]["cull_min_triangles"] = cull_min_triangles;
  j["collisions"]["reuse_front"] = reuse_front;
  return parse_scene(j, "swing.json");
}

bool same_bytes(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

struct Frames {
  std::vector<FrameStats> frames;
  std::vector<std::vector<Vec3>> x, v;
};

Frames run(const std::string& culling, const std::string& policy, int threads = 2,
           int cull_min_triangles = 16, bool reuse_front = false) {
  Simulation sim(swinging_sheet(culling, policy, cull_min_triangles, reuse_front));
  Frames r;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    for (int f = 0; f < kFrames; ++f) {
      r.frames.push_back(sim.advance_frame());
      r.x.push_back(sim.state().x);
      r.v.push_back(sim.state().v);
    }
  });
  return r;
}

// The collision stage's part times are disjoint pieces of its wall time: each is non-negative,
// together they stay within collision_seconds, and the self detector's full passes, whose own
// phase times self_ccd reports, lie inside the self detector's calls.
TEST(SelfCulling, CollisionPartTimesAreDisjointPiecesOfTheStage) {
  const Frames r = run("sound", "proposed");
  for (int f = 0; f < kFrames; ++f) {
    const FrameStats& s = r.frames[f];
    const CollisionPartTimes& p = s.collision_parts;
    for (double x : {p.setup_s, p.crossings_s, p.proximity_s, p.response_s, p.ccd_self_s,
                     p.ccd_body_s, p.ccd_hits_s, p.zones_s})
      EXPECT_GE(x, 0.0) << "frame " << f + 1;
    EXPECT_GT(p.proximity_s, 0.0) << "frame " << f + 1;
    EXPECT_GT(p.ccd_self_s, 0.0) << "frame " << f + 1;
    EXPECT_GT(p.ccd_body_s, 0.0) << "frame " << f + 1;
    EXPECT_LE(p.total(), s.collision.seconds + 1e-9) << "frame " << f + 1;
    EXPECT_LE(s.self_ccd.refit_s + s.self_ccd.traversal_s + s.self_ccd.narrow_s,
              p.ccd_self_s + 1e-9)
        << "frame " << f + 1;
  }
}

TEST(SelfCulling, EverySettingGivesTheSameFramesBitwise) {
  const Frames none = run("none", "proposed");
  long long hits = 0, pairs_none = 0;
  for (int f = 0; f < kFrames; ++f) {
    const FrameStats& s = none.frames[f];
    EXPECT_EQ(s.self_ccd.nodes_culled, 0) << "frame " << f + 1;
    EXPECT_GE(s.self_ccd.calls, s.substeps);  // the first pass of every substep is full
    EXPECT_GE(s.self_proximity.calls, s.substeps);
    hits += s.collision.ccd_hits;
    pairs_none += s.self_ccd.triangle_pairs;
  }
  EXPECT_GT(hits, 0);  // contact happened
  // Every policy at the simulator's threshold, and PROPOSED testing every node.
  for (const auto& [policy, threshold] : {std::pair{"provot", 16}, std::pair{"proposed", 16},
                                          std::pair{"exact", 16}, std::pair{"proposed", 0}}) {
    const Frames sound = run("sound", policy, 2, threshold);
    long long culled = 0, pairs = 0;
    for (int f = 0; f < kFrames; ++f) {
      const FrameStats &a = none.frames[f], &b = sound.frames[f];
      ASSERT_TRUE(same_bytes(none.x[f], sound.x[f])) << policy << " frame " << f + 1;
      ASSERT_TRUE(same_bytes(none.v[f], sound.v[f])) << policy << " frame " << f + 1;
      EXPECT_EQ(a.collision.ccd_hits, b.collision.ccd_hits) << policy << " frame " << f + 1;
      EXPECT_EQ(a.collision.proximity_pairs, b.collision.proximity_pairs)
          << policy << " frame " << f + 1;
      EXPECT_EQ(a.self_ccd.calls, b.self_ccd.calls) << policy << " frame " << f + 1;
      EXPECT_EQ(a.self_proximity.calls, b.self_proximity.calls) << policy << " frame " << f + 1;
      EXPECT_EQ(a.self_proximity.pairs, b.self_proximity.pairs) << policy << " frame " << f + 1;
      // Culled nodes only drop pairs the kernels could not reach.
      EXPECT_LE(b.self_ccd.triangle_pairs, a.self_ccd.triangle_pairs)
          << policy << " frame " << f + 1;
      culled += b.self_ccd.nodes_culled;
      pairs += b.self_ccd.triangle_pairs;
    }
    EXPECT_GT(culled, 0) << policy;  // the cones were in the loop
    EXPECT_LT(pairs, pairs_none) << policy;
  }
}

// The detectors' traversal front (collisions.reuse_front) changes the traversal's cost only.
TEST(SelfCulling, TheTraversalFrontGivesTheSameFramesBitwise) {
  for (const char* culling : {"none", "sound"}) {
    const Frames plain = run(culling, "proposed"), front = run(culling, "proposed", 2, 16, true);
    for (int f = 0; f < kFrames; ++f) {
      const FrameStats &a = plain.frames[f], &b = front.frames[f];
      ASSERT_TRUE(same_bytes(plain.x[f], front.x[f])) << culling << " frame " << f + 1;
      ASSERT_TRUE(same_bytes(plain.v[f], front.v[f])) << culling << " frame " << f + 1;
      EXPECT_EQ(a.collision.ccd_hits, b.collision.ccd_hits) << culling << " frame " << f + 1;
      EXPECT_EQ(a.self_ccd.calls, b.self_ccd.calls) << culling << " frame " << f + 1;
      EXPECT_EQ(a.self_ccd.triangle_pairs, b.self_ccd.triangle_pairs)
          << culling << " frame " << f + 1;
      EXPECT_EQ(a.self_ccd.nodes_culled, b.self_ccd.nodes_culled) << culling << " frame " << f + 1;
    }
  }
}

TEST(SelfCulling, FrameFiguresDoNotDependOnTheThreadCount) {
  const Frames one = run("sound", "proposed", 1), two = run("sound", "proposed", 2);
  for (int f = 0; f < kFrames; ++f) {
    const FrameStats &a = one.frames[f], &b = two.frames[f];
    ASSERT_TRUE(same_bytes(one.x[f], two.x[f])) << "frame " << f + 1;
    EXPECT_EQ(a.self_ccd.calls, b.self_ccd.calls) << "frame " << f + 1;
    EXPECT_EQ(a.self_ccd.triangle_pairs, b.self_ccd.triangle_pairs) << "frame " << f + 1;
    EXPECT_EQ(a.self_ccd.nodes_culled, b.self_ccd.nodes_culled) << "frame " << f + 1;
    EXPECT_EQ(a.self_proximity.calls, b.self_proximity.calls) << "frame " << f + 1;
    EXPECT_EQ(a.self_proximity.reused_pairs, b.self_proximity.reused_pairs) << "frame " << f + 1;
    EXPECT_EQ(a.self_proximity.pairs, b.self_proximity.pairs) << "frame " << f + 1;
  }
}

}  // namespace
}  // namespace clothcd::sim
