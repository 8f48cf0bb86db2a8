// Scene JSON validation, procedural scenes, the substep rule and OBJ reading.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/sim/scene.hpp"
#include "clothcd/sim/sewing.hpp"
#include "clothcd/sim/simulation.hpp"
#include "sim/scene_json.hpp"
#include "support/data.hpp"

namespace clothcd::sim {
namespace {

using nlohmann::json;

json small_grid_scene() {
  return json::parse(R"({
    "name": "small",
    "frames": 2,
    "cloth": {"grid": {"origin": [0, 1, 0], "u": [0.2, 0, 0], "v": [0, 0, 0.2], "resolution": [4, 4]}},
    "pins": [{"grid_edge": "u0"}]
  })");
}

/// The InputError message of parsing `j`, or "" when it parsed.
std::string error_of(const json& j) {
  try {
    (void)parse_scene(j, "test-scene.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Scene, TextEqualsParsedJson) {
  const Scene a = parse_scene(small_grid_scene(), "test-scene.json");
  const Scene b = parse_scene_text(small_grid_scene().dump(), "test-scene.json");
  EXPECT_EQ(a.cloth.positions, b.cloth.positions);
  EXPECT_EQ(a.cloth.faces, b.cloth.faces);
  EXPECT_EQ(a.frames, b.frames);
  ASSERT_EQ(a.pins.size(), b.pins.size());
  try {
    (void)parse_scene_text("{\"frames\": 2,", "broken.json");
    ADD_FAILURE() << "a truncated document parsed";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("broken.json"), std::string::npos) << m;
    EXPECT_NE(m.find("invalid JSON"), std::string::npos) << m;
  }
}

TEST(Scene, SmallGridParses) {
  const Scene s = parse_scene(small_grid_scene(), "test-scene.json");
  EXPECT_EQ(s.cloth.positions.size(), 25u);
  EXPECT_EQ(s.cloth.faces.size(), 32u);
  ASSERT_EQ(s.pins.size(), 1u);
  EXPECT_EQ(s.pins[0].vertices.size(), 5u);
  EXPECT_EQ(s.frames, 2);
}

TEST(Scene, ZoneMotionIsAffineUnlessTheSceneSaysRigid) {
  json j = small_grid_scene();
  EXPECT_TRUE(parse_scene(j, "test-scene.json").contact.affine_zones);
  j["collisions"] = {{"zone_motion", "rigid"}};
  EXPECT_FALSE(parse_scene(j, "test-scene.json").contact.affine_zones);
}

TEST(Scene, SelfCcdUsesSoundCullingUnlessTheSceneSaysNone) {
  json j = small_grid_scene();
  const Scene s = parse_scene(j, "test-scene.json");
  EXPECT_EQ(s.contact.culling, Culling::Sound);
  EXPECT_EQ(s.contact.cone_policy, ConePolicy::Proposed);
  j["collisions"] = {{"culling", "none"}, {"cone_policy", "provot"}};
  const Scene none = parse_scene(j, "test-scene.json");
  EXPECT_EQ(none.contact.culling, Culling::None);
  EXPECT_EQ(none.contact.cone_policy, ConePolicy::Provot);
  j["collisions"] = {{"culling", "sound"}, {"cone_policy", "exact"}};
  const Scene exact = parse_scene(j, "test-scene.json");
  EXPECT_EQ(exact.contact.culling, Culling::Sound);
  EXPECT_EQ(exact.contact.cone_policy, ConePolicy::Exact);
  j["collisions"] = {{"cone_policy", "proposed"}};
  EXPECT_EQ(parse_scene(j, "test-scene.json").contact.cone_policy, ConePolicy::Proposed);
  EXPECT_EQ(s.contact.cull_min_triangles, 16);
  j["collisions"] = {{"cull_min_triangles", 0}};
  EXPECT_EQ(parse_scene(j, "test-scene.json").contact.cull_min_triangles, 0);
  j["collisions"] = {{"cull_min_triangles", -1}};
  EXPECT_THROW((void)parse_scene(j, "test-scene.json"), InputError);
  j["collisions"] = {{"cull_min_triangles", 2.5}};
  EXPECT_THROW((void)parse_scene(j, "test-scene.json"), InputError);
}

TEST(Scene, UnresolvedHitsHalveTheSubstepUnlessTheSceneSaysNot) {
  json j = small_grid_scene();
  EXPECT_TRUE(parse_scene(j, "test-scene.json").solver.halve_unresolved);
  j["solver"] = {{"halve_unresolved", false}};
  EXPECT_FALSE(parse_scene(j, "test-scene.json").solver.halve_unresolved);
}

TEST(Scene, FirstSolveStopsAtTheReleaseToleranceTheSceneGives) {
  json j = small_grid_scene();
  EXPECT_EQ(parse_scene(j, "test-scene.json").solver.release_tolerance, 1e-2);
  j["solver"] = {{"release_tolerance", 1e-3}};
  EXPECT_EQ(parse_scene(j, "test-scene.json").solver.release_tolerance, 1e-3);
  j["solver"] = {{"release_tolerance", 2.0}};
  EXPECT_THROW((void)parse_scene(j, "test-scene.json"), InputError);
}

TEST(Scene, FastFramesKeepThePcgToleranceUnlessTheSceneGivesOne) {
  json j = small_grid_scene();
  EXPECT_EQ(parse_scene(j, "test-scene.json").solver.fast_pcg_tolerance, 0.0);
  j["solver"] = {{"fast_pcg_tolerance", 3e-3}};
  EXPECT_EQ(parse_scene(j, "test-scene.json").solver.fast_pcg_tolerance, 3e-3);
  j["solver"] = {{"fast_pcg_tolerance", -1e-3}};
  EXPECT_NE(error_of(j).find("fast_pcg_tolerance"), std::string::npos) << error_of(j);
}

// A tolerance above halve_residual would halve every substep it solves: an error, unless halving
// is off or halve_residual is raised with it.
TEST(Scene, ToleranceAboveTheHalvingResidualIsAnError) {
  json j = small_grid_scene();
  for (const char* key : {"pcg_tolerance", "fast_pcg_tolerance"}) {
    j["solver"] = {{key, 0.05}};
    const std::string e = error_of(j);
    EXPECT_NE(e.find(std::string("solver.") + key + "': 0.05 is above halve_residual (0.01)"),
              std::string::npos)
        << e;
    j["solver"] = {{key, 0.05}, {"max_halvings", 0}};
    EXPECT_EQ(error_of(j), "");
    j["solver"] = {{key, 0.05}, {"halve_residual", 0.05}};
    EXPECT_EQ(error_of(j), "");
  }
  j["solver"] = {{"fast_pcg_tolerance", 0.01}};
  EXPECT_EQ(error_of(j), "");
}

// The first frame starts at rest (the floor of substeps), the second falling (the cloth rule asks
// for more): only the second is a fast frame.
TEST(Scene, OnlyFramesAboveTheSubstepFloorUseTheFastTolerance) {
  json j = small_grid_scene();
  j.erase("pins");
  j["substeps"] = {{"min", 2}, {"max", 8}, {"cloth_displacement", 1e-3}};
  j["solver"] = {{"pcg_tolerance", 1e-6}, {"fast_pcg_tolerance", 1e-3}};
  Simulation sim(parse_scene(j, "test-scene.json"));
  const FrameStats first = sim.advance_frame();
  const FrameStats second = sim.advance_frame();
  EXPECT_EQ(first.substeps, 2);
  EXPECT_EQ(first.pcg_tolerance, 1e-6);
  EXPECT_GT(second.substeps, 2);
  EXPECT_EQ(second.pcg_tolerance, 1e-3);
}

TEST(Scene, CoarseCorrectionIsOffUnlessTheSceneGivesAnAggregateSize) {
  json j = small_grid_scene();
  EXPECT_EQ(parse_scene(j, "test-scene.json").solver.coarse_aggregate, 0);
  j["solver"] = {{"coarse_aggregate", 64}};
  EXPECT_EQ(parse_scene(j, "test-scene.json").solver.coarse_aggregate, 64);
  j["solver"] = {{"coarse_aggregate", -1}};
  EXPECT_THROW((void)parse_scene(j, "test-scene.json"), InputError);
  j["solver"] = {{"coarse_aggregate", 1}};  // one vertex per aggregate is block Jacobi again
  EXPECT_THROW((void)parse_scene(j, "test-scene.json"), InputError);
}

TEST(Scene, RepulsionIsPointwiseAndContactsEnterTheSolveUnlessTheSceneSaysNot) {
  json j = small_grid_scene();
  const Scene on = parse_scene(j, "test-scene.json");
  EXPECT_TRUE(on.contact.pointwise_repulsion);
  EXPECT_TRUE(on.contact.body_constraints);
  EXPECT_TRUE(on.contact.coupled_contacts);
  j["collisions"] = {
      {"pointwise_repulsion", false}, {"body_constraints", false}, {"coupled_contacts", false}};
  const Scene off = parse_scene(j, "test-scene.json");
  EXPECT_FALSE(off.contact.pointwise_repulsion);
  EXPECT_FALSE(off.contact.body_constraints);
  EXPECT_FALSE(off.contact.coupled_contacts);
}

TEST(Scene, ValidationErrorsNameFileAndKey) {
  struct Case {
    const char* name;
    std::function<void(json&)> edit;
    const char* expect;  // substring of the message
  };
  const std::vector<Case> cases = {
      {"unknown top key", [](json& j) { j["framez"] = 3; }, "'framez': unknown key"},
      {"unknown nested key", [](json& j) { j["cloth"]["grid"]["resolutoin"] = 1; },
       "'cloth.grid.resolutoin': unknown key"},
      {"wrong type", [](json& j) { j["frames"] = "many"; }, "'frames': expected an integer"},
      {"missing name", [](json& j) { j.erase("name"); }, "'name': missing"},
      {"bad vector",
       [](json& j) {
         j["gravity"] = json::array({0, 1});
       },
       "'gravity': expected an array of 3 numbers"},
      {"out of range",
       [](json& j) {
         j["material"] = {{"poisson", 0.7}};
       },
       "'material.poisson': 0.7 is outside"},
      {"bad boolean",
       [](json& j) {
         j["solver"] = {{"halve_unresolved", 1}};
       },
       "'solver.halve_unresolved': expected true or false"},
      {"bad contact boolean",
       [](json& j) {
         j["collisions"] = {{"body_constraints", "yes"}};
       },
       "'collisions.body_constraints': expected true or false"},
      {"bad coupling boolean",
       [](json& j) {
         j["collisions"] = {{"coupled_contacts", "yes"}};
       },
       "'collisions.coupled_contacts': expected true or false"},
      {"bad enum",
       [](json& j) {
         j["output"] = {{"format", "stl"}};
       },
       "'output.format': 'stl' is not one of"},
      {"missing file",
       [](json& j) {
         j["cloth"] = {{"obj", "no/such/cloth.obj"}};
       },
       "'cloth.obj': file"},
      {"pin out of range",
       [](json& j) {
         j["pins"] = json::array({{{"vertices", {0, 999}}}});
       },
       "'pins[0].vertices': 999 is not a vertex id"},
      {"bad body type",
       [](json& j) {
         j["body"] = {{"type", "cube"}};
       },
       "'body.type'"},
      {"bad zone motion",
       [](json& j) {
         j["collisions"] = {{"zone_motion", "bent"}};
       },
       "'collisions.zone_motion': 'bent' is not one of"},
      {"unsound culling",
       [](json& j) {
         j["collisions"] = {{"culling", "cone"}};
       },
       "'collisions.culling': 'cone' is not one of"},
      {"culling not a string",
       [](json& j) {
         j["collisions"] = {{"culling", true}};
       },
       "'collisions.culling': expected a string"},
      {"bad cone policy",
       [](json& j) {
         j["collisions"] = {{"cone_policy", "optimal"}};
       },
       "'collisions.cone_policy': 'optimal' is not one of"},
      {"frames without placeholder",
       [](json& j) {
         j["body"] = {{"type", "frames"}, {"frames", "x.obj"}, {"count", 2}};
       },
       "'{}' standing for the frame number"},
  };
  for (const Case& c : cases) {
    json j = small_grid_scene();
    c.edit(j);
    const std::string msg = error_of(j);
    EXPECT_NE(msg.find("test-scene.json"), std::string::npos) << c.name << ": " << msg;
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.name << ": " << msg;
  }
}

// Found by fuzz_scene: a number beyond double's range made nlohmann throw out_of_range (not a
// parse_error), which escaped load_scene as a bare json exception.
TEST(Scene, HugeNumberIsAnInputError) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / "clothcd_scene_huge_number.json";
  {
    std::ofstream out(file);
    out << "{\"name\": \"x\", \"frames\": 3333E0010613521}";
  }
  try {
    (void)load_scene(file);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("invalid JSON"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
  std::filesystem::remove(file);
}

TEST(Scene, SubstepRule) {
  const SubstepRule r;
  EXPECT_EQ(r.count(0.0), 4);
  EXPECT_EQ(r.count(0.083), 4);
  EXPECT_EQ(r.count(0.2), 5);
  EXPECT_EQ(r.count(0.66), 17);  // the fastest Kick frame, as in docs/simulator.md 4
  EXPECT_EQ(r.count(10.0), 32);
}

TEST(Scene, ClothSpeedQuantileIgnoresTheFewFastestVertices) {
  std::vector<Vec3> v(2000, Vec3(0.0, 0.1, 0.0));
  v[7] = Vec3(3.0, 0.0, 4.0);  // one vertex at 5 m/s
  v[1500] = Vec3(0.0, -0.3, 0.0);
  SubstepRule r;
  EXPECT_DOUBLE_EQ(r.cloth_speed(v), 5.0);  // default: the fastest
  r.cloth_speed_quantile = 0.9985;          // rank 1997 of 2000
  EXPECT_DOUBLE_EQ(r.cloth_speed(v), 0.1);
  r.cloth_speed_quantile = 0.99949;  // rank 1999: the second fastest
  EXPECT_DOUBLE_EQ(r.cloth_speed(v), 0.3);
  r.cloth_speed_quantile = 1e-6;  // the slowest
  EXPECT_DOUBLE_EQ(r.cloth_speed(v), 0.1);
  EXPECT_DOUBLE_EQ(r.cloth_speed({}), 0.0);
}

std::filesystem::path repo_scene(const char* name) {
  return std::filesystem::path(CLOTHCD_SOURCE_DIR) / "scenes" / name;
}

TEST(Scene, ProceduralScenesLoadWithoutData) {
  for (const char* name : {"sphere-drop.json", "twist.json"}) {
    const Scene s = load_scene(repo_scene(name));
    EXPECT_GE(s.cloth.faces.size(), 20000u) << name;
    EXPECT_TRUE(s.body || !s.pins.empty()) << name;
  }
}

TEST(Scene, DataScenesLoad) {
  CLOTHCD_REQUIRE_DATA(body, "body/rumba/0.obj");
  const Scene s = load_scene(repo_scene("dress-rumba.json"));
  EXPECT_EQ(s.cloth.positions.size(), 15656u);
  EXPECT_EQ(s.cloth.faces.size(), 29456u);
  EXPECT_EQ(s.cloth.stitches.size(), 851u);
  EXPECT_EQ(s.cloth.pattern.size(), 15656u);
  ASSERT_TRUE(s.body);
  EXPECT_EQ(s.body->num_vertices(), 12811);
  // Frame 0 of the motion is the drape's pose once the drape is lifted by 0.75 m.
  std::vector<Vec3> b0;
  s.body->positions_at(0.0, b0);
  const TriangleMesh drape = clothcd::read_obj(body.parent_path().parent_path().parent_path() /
                                               "garments/dress_knife/drape.obj");
  double worst = 0.0;
  for (int i = 0; i < 12811; ++i) {
    worst = std::max(worst, (drape.vertices[15656 + i] + Vec3(0, 0.75, 0) - b0[i]).norm());
  }
  EXPECT_LT(worst, 1e-3);
}

TEST(Sewing, RecoversTiesBetweenPanels) {
  // Two unit squares side by side, 0.5 mm apart: each boundary vertex on the gap ties across.
  std::vector<Vec3> x{{0, 0, 0},      {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                      {1.0005, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1.0005, 1, 0}};
  std::vector<Face> f{{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  const auto ties = recover_stitches(x, f, 1e-3);
  ASSERT_EQ(ties.size(), 4u);
  EXPECT_EQ(ties[0].a, 1);
  EXPECT_EQ(ties[1].a, 2);
  EXPECT_EQ(ties[2].a, 4);
  EXPECT_EQ(ties[3].a, 7);
  EXPECT_TRUE(recover_stitches(x, f, 1e-4).empty());
}

}  // namespace
}  // namespace clothcd::sim
