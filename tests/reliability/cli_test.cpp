// The command line on bad input and on failing output: exit codes, messages naming the file and
// what was wrong, and nothing partial left on disk; and its determinism (detect across thread
// counts, simulate across runs). Runs the built `clothcd` binary (CLOTHCD_CLI).

#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/triangle_mesh.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd {
namespace {

using test::CliScratch;
using Files = std::vector<std::string>;

// `trap '' XFSZ` is inherited by clothcd, so a write past the limit fails with EFBIG (as a full
// disk fails with ENOSPC) instead of killing it; `ulimit -f 1` allows 1024 bytes per file.
const char* kDiskFull = "trap '' XFSZ; ulimit -f 1;";

TriangleMesh frame(const research::ProceduralScene& s, const Positions& v) {
  TriangleMesh m;
  m.faces = s.faces;
  for (Eigen::Index i = 0; i < v.rows(); ++i)
    m.vertices.emplace_back(v(i, 0), v(i, 1), v(i, 2));
  return m;
}

// A crumpled sheet stepped into self-contact: t0.obj and t1.obj in the scratch folder.
void write_step(const CliScratch& dir) {
  const research::ProceduralScene s = research::crumpled_sheet(16, 7);
  write_obj(dir / "t0.obj", frame(s, s.v_t0));
  write_obj(dir / "t1.obj", frame(s, s.v_t1));
}

std::string obj_text(const std::string& v3) {
  return "v 0 0 0\nv 1 0 0\nv 0 1 0\nv " + v3 + "\nf 1 2 3\nf 2 4 3\n";
}

TEST(CliDetect, NonFiniteCoordinateInT1) {
  CliScratch dir;
  dir.write("t0.obj", obj_text("1 1 0"));
  dir.write("t1.obj", obj_text("1 nan 0"));
  const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --json out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("t1.obj:4:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not finite"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files(), (Files{"t0.obj", "t1.obj"}));
}

TEST(CliDetect, T1WithAnotherVertexCount) {
  CliScratch dir;
  dir.write("t0.obj", obj_text("1 1 0"));
  dir.write("t1.obj", obj_text("1 1 0") + "v 2 2 2\n");
  const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --json out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("t0.obj"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("t1.obj"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files(), (Files{"t0.obj", "t1.obj"}));
}

TEST(CliDetect, FaceIndexOutOfRangeInPly) {
  CliScratch dir;
  dir.write("t0.obj", obj_text("1 1 0"));
  dir.write("t1.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  const auto r = dir.run("detect --t0 t0.obj --t1 t1.ply --json out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("t1.ply"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("out of range"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files(), (Files{"t0.obj", "t1.ply"}));
}

TEST(CliDetect, MissingInput) {
  CliScratch dir;
  dir.write("t0.obj", obj_text("1 1 0"));
  const auto r = dir.run("detect --t0 t0.obj --t1 nope.obj --json out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("nope.obj"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files(), (Files{"t0.obj"}));
}

TEST(CliDetect, EmptyMesh) {
  CliScratch dir;
  dir.write("t0.obj", "");
  dir.write("t1.obj", "");
  const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("t0.obj"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no faces"), std::string::npos) << r.err;
}

TEST(CliDetect, UnknownOptionValue) {
  CliScratch dir;
  write_step(dir);
  const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --culling maybe --json out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--culling"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files(), (Files{"t0.obj", "t1.obj"}));
}

TEST(CliDetect, JsonInMissingFolder) {
  CliScratch dir;
  write_step(dir);
  const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --json no/such/out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("no/such/out.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cannot write"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files(), (Files{"t0.obj", "t1.obj"}));
}

TEST(CliDetect, JsonOnFullDiskLeavesOldFileAlone) {
  CliScratch dir;
  write_step(dir);
  // The result is well over the 1 KiB limit (checked), and the old out.json must survive.
  ASSERT_EQ(dir.run("detect --t0 t0.obj --t1 t1.obj --json full.json").code, 0);
  ASSERT_GT(std::filesystem::file_size(dir / "full.json"), 4096u);
  std::filesystem::remove(dir / "full.json");
  dir.write("out.json", "{\"old\": true}\n");
  const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --json out.json", kDiskFull);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("out.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("write failed"), std::string::npos) << r.err;
  EXPECT_EQ(CliScratch::slurp(dir / "out.json"), "{\"old\": true}\n");
  EXPECT_EQ(dir.files(), (Files{"out.json", "t0.obj", "t1.obj"}));
}

// The JSON of `detect` without its wall-clock fields.
nlohmann::json without_times(nlohmann::json j) {
  for (const char* k : {"time_refit", "time_traverse", "time_narrow"})
    j["stats"].erase(k);
  return j;
}

TEST(CliDeterminism, DetectSameForOneTwoAndFourThreads) {
  CliScratch dir;
  write_step(dir);
  std::vector<nlohmann::json> results;
  for (int threads : {1, 2, 4}) {
    for (const char* culling : {"none", "sound"}) {
      const std::string out =
          std::string("t").append(std::to_string(threads)).append(culling) + ".json";
      const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --culling " + std::string(culling) +
                             " --threads " + std::to_string(threads) + " --json " + out);
      ASSERT_EQ(r.code, 0) << r.err;
      results.push_back(without_times(nlohmann::json::parse(CliScratch::slurp(dir / out))));
    }
  }
  ASSERT_GT(results[0]["vf"].size() + results[0]["ee"].size(), 0u) << "no collisions to compare";
  for (std::size_t k = 2; k < results.size(); ++k) {
    EXPECT_EQ(results[k], results[k % 2]) << "threads run " << k / 2 << ", culling " << k % 2;
  }
  // The same collisions whatever the culling (the sound mode misses none).
  EXPECT_EQ(results[0]["vf"], results[1]["vf"]);
  EXPECT_EQ(results[0]["ee"], results[1]["ee"]);
}

TEST(CliDetect, JsonHoldsTheDetectorsCollisionsExactly) {
  // The JSON is written directly (not through a JSON library): it must parse, and hold exactly
  // the library's collisions, vertex ids and times of impact bit for bit, with --verify's lists.
  CliScratch dir;
  write_step(dir);
  const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --culling cone --verify --json out.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(CliScratch::slurp(dir / "out.json"));
  const TriangleMesh m0 = read_mesh(dir / "t0.obj"), m1 = read_mesh(dir / "t1.obj");
  research::DetectOptions o;
  o.research.culling = research::CullingRule::Cone;
  o.research.verify = true;
  research::SelfDetector det(m0.faces, m0.num_vertices(), vertices_matrix(m0), o);
  const research::DetectResult want = det.detect(vertices_matrix(m0), vertices_matrix(m1));
  ASSERT_GT(want.vf.size() + want.ee.size(), 0u) << "no collisions to compare";
  const auto vf_json = [](const std::vector<VertexFaceCollision>& list) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& c : list) {
      out.push_back({{"vertex", c.vertex},
                     {"face", {c.face_vertices[0], c.face_vertices[1], c.face_vertices[2]}},
                     {"toi", c.toi}});
    }
    return out;
  };
  const auto ee_json = [](const std::vector<EdgeEdgeCollision>& list) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& c : list) {
      out.push_back({{"edge_a", {c.edge_a_vertices[0], c.edge_a_vertices[1]}},
                     {"edge_b", {c.edge_b_vertices[0], c.edge_b_vertices[1]}},
                     {"toi", c.toi}});
    }
    return out;
  };
  EXPECT_EQ(j["vf"], vf_json(want.vf));
  EXPECT_EQ(j["ee"], ee_json(want.ee));
  EXPECT_EQ(j["missed_vf"], vf_json(want.verification.missed_vf));
  EXPECT_EQ(j["missed_ee"], ee_json(want.verification.missed_ee));
  for (const auto& c : j["ee"])
    EXPECT_TRUE(c["toi"].is_number_float()) << c;
  EXPECT_EQ(j["stats"]["triangle_pairs"].get<std::uint64_t>(), want.stats.triangle_pairs);
  EXPECT_EQ(j["stats"]["ee_collisions"].get<std::uint64_t>(), want.ee.size());
  EXPECT_EQ(j.size(), 5u) << "vf, ee, missed_vf, missed_ee, stats";
}

TEST(CliDetect, EarliestWritesTheQuerysAnswer) {
  // --earliest: the library's earliest impact, its pair as the input's vertex ids, and the
  // stats keys of a full detection; --toi-tolerance reaches the query.
  CliScratch dir;
  write_step(dir);
  const TriangleMesh m0 = read_mesh(dir / "t0.obj"), m1 = read_mesh(dir / "t1.obj");
  SelfDetector det(m0.faces, m0.num_vertices(), vertices_matrix(m0));
  for (const double tol : {1e-6, 1e-3}) {
    const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --earliest --toi-tolerance " +
                           std::to_string(tol) + " --json out.json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(CliScratch::slurp(dir / "out.json"));
    EarliestOptions eo;
    eo.toi_tolerance = std::stod(std::to_string(tol));
    const EarliestImpact want = det.earliest_impact(vertices_matrix(m0), vertices_matrix(m1), eo);
    ASSERT_NE(want.kind, EarliestImpact::Kind::None);
    EXPECT_EQ(j["earliest"]["toi"].get<double>(), want.toi);
    const Topology& t = det.topology();
    if (want.kind == EarliestImpact::Kind::VertexFace) {
      const Face& f = t.faces()[want.ids[1]];
      EXPECT_EQ(j["earliest"]["kind"], "vf");
      EXPECT_EQ(j["earliest"]["ids"], nlohmann::json({want.ids[0], {f[0], f[1], f[2]}}));
    } else {
      const Edge &a = t.edges()[want.ids[0]], &b = t.edges()[want.ids[1]];
      EXPECT_EQ(j["earliest"]["kind"], "ee");
      EXPECT_EQ(j["earliest"]["ids"], nlohmann::json({{a[0], a[1]}, {b[0], b[1]}}));
    }
    for (const char* key : {"time_refit", "time_traverse", "time_narrow", "triangle_pairs"})
      EXPECT_TRUE(j["stats"].contains(key)) << key;
    EXPECT_EQ(j.size(), 2u) << "earliest, stats";
  }
  // --repeat N: N more calls on the same detector, their times listed; the answer is the same.
  {
    const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --earliest --repeat 2 --json rep.json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(CliScratch::slurp(dir / "rep.json"));
    const EarliestImpact want = det.earliest_impact(vertices_matrix(m0), vertices_matrix(m1));
    EXPECT_EQ(j["earliest"]["toi"].get<double>(), want.toi);
    ASSERT_EQ(j["repeat"].size(), 2u);
    for (const auto& call : j["repeat"]) {
      for (const char* key : {"time_refit", "time_traverse", "time_narrow"})
        EXPECT_GE(call[key].get<double>(), 0.0) << key;
    }
  }
  // Settings it cannot honour: an error, and no output file.
  for (const char* bad :
       {"--earliest --first-window 0.3", "--earliest --table", "--first-window 0.5",
        "--earliest --toi-tolerance 0", "--repeat 2", "--earliest --repeat -1"}) {
    const auto r =
        dir.run(std::string("detect --t0 t0.obj --t1 t1.obj ") + bad + " --json bad.json");
    EXPECT_NE(r.code, 0) << bad;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.json")) << bad;
  }
}

TEST(CliDetect, ThicknessReportsTrianglePairsCulledWhole) {
  // The whole-triangle distance bound culls whole triangle pairs first: the count is in the JSON
  // and the summary. With a thickness it is part of the distance filter; at zero thickness it
  // runs unless --no-distance-filter asks for the cubic filter alone (then the count is 0), and
  // the collisions are the same either way.
  CliScratch dir;
  write_step(dir);
  std::map<std::string, nlohmann::json> out;
  for (const char* args :
       {"--thickness 0", "--thickness 0 --no-distance-filter", "--thickness 0.001"}) {
    SCOPED_TRACE(args);
    const auto r =
        dir.run(std::string("detect --t0 t0.obj --t1 t1.obj ") + args + " --json out.json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(CliScratch::slurp(dir / "out.json"));
    const auto apart = j["stats"]["triangle_pairs_apart"].get<std::uint64_t>();
    const auto pairs = j["stats"]["triangle_pairs"].get<std::uint64_t>();
    EXPECT_NE(r.out.find("culled whole by the triangle distance bound"), std::string::npos)
        << r.out;
    if (std::string(args).find("--no-distance-filter") != std::string::npos) {
      EXPECT_EQ(apart, 0u);
    } else {
      EXPECT_GT(apart, 0u);
      EXPECT_LT(apart, pairs);
    }
    out[args] = j;
  }
  const auto& with = out["--thickness 0"];
  const auto& without = out["--thickness 0 --no-distance-filter"];
  EXPECT_EQ(with["vf"], without["vf"]);
  EXPECT_EQ(with["ee"], without["ee"]);
  EXPECT_EQ(with["stats"]["triangle_pairs"], without["stats"]["triangle_pairs"]);
  EXPECT_LT(with["stats"]["ee_tests"].get<std::uint64_t>(),
            without["stats"]["ee_tests"].get<std::uint64_t>());
}

TEST(CliDetect, PrintsItsPhasesAndSetupTimes) {
  // The summary's last lines: the detection's phases, then reading and building the detector,
  // each a time in seconds.
  CliScratch dir;
  write_step(dir);
  const auto r = dir.run("detect --t0 t0.obj --t1 t1.obj --culling sound");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::regex times(
      R"(time: refit [0-9.]+ s, traversal [0-9.]+ s, narrow phase [0-9.]+ s\n)"
      R"(setup: reading [0-9.]+ s, detector [0-9.]+ s \(topology, tree, orphans, ownership\)\n$)");
  EXPECT_TRUE(std::regex_search(r.out, times)) << r.out;
}

TEST(CliDetect, CullMinTrianglesSameCollisionsFewerConeTests) {
  CliScratch dir;
  write_step(dir);
  std::vector<nlohmann::json> results;
  for (const char* threshold : {"0", "16"}) {
    const std::string out = std::string("min") + threshold + ".json";
    const auto r = dir.run(std::string("detect --t0 t0.obj --t1 t1.obj --culling sound --bvh patch "
                                       "--cull-min-triangles ") +
                           threshold + " --json " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    results.push_back(nlohmann::json::parse(CliScratch::slurp(dir / out)));
  }
  EXPECT_EQ(results[0]["vf"], results[1]["vf"]);
  EXPECT_EQ(results[0]["ee"], results[1]["ee"]);
  const auto tests0 = results[0]["stats"]["cone_tests"].get<std::uint64_t>();
  const auto tests16 = results[1]["stats"]["cone_tests"].get<std::uint64_t>();
  EXPECT_GT(tests16, 0u);
  EXPECT_LT(tests16, tests0);
  const auto bad = dir.run("detect --t0 t0.obj --t1 t1.obj --cull-min-triangles -1 --json x.json");
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--cull-min-triangles"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.json"));
}

TEST(CliCcdQueries, MalformedCsvWithJson) {
  CliScratch dir;
  // One query is 8 rows (4 points at t0 and t1) of "x_num,x_den,y_num,y_den,z_num,z_den,truth".
  std::string good;
  for (int k = 0; k < 8; ++k)
    good += "0,1," + std::to_string(k) + ",1,1,2,0\n";
  dir.write("q/vertex-face/a.csv", good);
  std::string bad = good;
  bad[bad.find('\n') + 1 + 2] = 'x';  // line 2, column 2
  dir.write("q/vertex-face/b.csv", bad);
  const auto r = dir.run("ccd-queries q --json out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("b.csv:2"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files(), (Files{"q/vertex-face/a.csv", "q/vertex-face/b.csv"}));
}

TEST(CliCcdQueries, NoCsvFiles) {
  CliScratch dir;
  std::filesystem::create_directories(dir / "empty");
  const auto r = dir.run("ccd-queries empty --json out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("no .csv files"), std::string::npos) << r.err;
  EXPECT_TRUE(dir.files().empty());
}

const char* kTinyScene = R"({"name": "tiny", "frames": 3, "frame_dt": 0.04,
 "cloth": {"grid": {"origin": [-0.3, 0.3, -0.3], "u": [0.6, 0, 0], "v": [0, 0, 0.6],
                    "resolution": [8, 8]}},
 "body": {"type": "sphere", "center": [0, 0, 0], "radius": 0.2, "subdivisions": 1},
 "pins": [{"grid_edge": "u0"}]})";

TEST(CliSimulate, UnknownKeyInScene) {
  CliScratch dir;
  std::string text = kTinyScene;
  text.replace(text.find("\"frames\""), 8, "\"framez\"");
  dir.write("s.json", text);
  const auto r = dir.run("simulate s.json --out out");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("s.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("framez"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(CliSimulate, TruncatedJson) {
  CliScratch dir;
  const std::string text = kTinyScene;
  dir.write("s.json", text.substr(0, text.size() / 2));
  const auto r = dir.run("simulate s.json --out out");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("invalid JSON"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(CliSimulate, BadValueAndMissingFile) {
  CliScratch dir;
  std::string text = kTinyScene;
  text.replace(text.find("[8, 8]"), 6, "[8, -1]");
  dir.write("s.json", text);
  auto r = dir.run("simulate s.json --out out");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("resolution"), std::string::npos) << r.err;
  dir.write("o.json", R"({"name": "o", "cloth": {"obj": "missing.obj"}})");
  r = dir.run("simulate o.json --out out");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("missing.obj"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(CliSimulate, OutputIsAFile) {
  CliScratch dir;
  dir.write("s.json", kTinyScene);
  dir.write("out", "not a folder");
  const auto r = dir.run("simulate s.json --out out");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("out"), std::string::npos) << r.err;
  EXPECT_EQ(CliScratch::slurp(dir / "out"), "not a folder");
}

TEST(CliSimulate, FullDiskLeavesNoPartialFile) {
  CliScratch dir;
  dir.write("s.json", kTinyScene);
  const auto r = dir.run("simulate s.json --out out", kDiskFull);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("cannot write 'out/frame_0000.obj'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(std::strerror(EFBIG)), std::string::npos) << r.err;
  for (const auto& f : dir.files()) {
    EXPECT_EQ(f.find(".tmp"), std::string::npos) << f;
  }
}

// The experiment harness writes every result through the same atomic writer: a full disk is
// reported, leaves no temporary, and finished results of an earlier run survive unchanged.
TEST(CliExperiment, FullDiskKeepsFinishedResults) {
  CliScratch dir;
  const std::string args = "experiment --scene fold@2 --out out --no-plots --threads 1";
  const auto first = dir.run(args);
  ASSERT_EQ(first.code, 0) << first.err;
  const std::string steps = CliScratch::slurp(dir / "out/steps.csv");
  ASSERT_GT(steps.size(), 1024u);  // over the 1 KiB limit below, so rewriting it must fail

  const auto full =
      dir.run("experiment --scene fold@3 --out out --no-plots --threads 1", kDiskFull);
  EXPECT_NE(full.code, 0);
  EXPECT_NE(full.err.find("cannot write"), std::string::npos) << full.err;
  EXPECT_NE(full.err.find(std::strerror(EFBIG)), std::string::npos) << full.err;
  EXPECT_EQ(CliScratch::slurp(dir / "out/steps.csv"), steps);
  for (const auto& f : dir.files()) {
    EXPECT_EQ(f.find(".tmp"), std::string::npos) << f;
  }
}

TEST(CliSimulate, ResumeFromDamagedOutput) {
  CliScratch dir;
  dir.write("s.json", kTinyScene);
  ASSERT_EQ(dir.run("simulate s.json --frames 1 --out out").code, 0);
  const std::string manifest = CliScratch::slurp(dir / "out/manifest.json");
  const std::string frame1 = CliScratch::slurp(dir / "out/frame_0001.obj");
  ASSERT_FALSE(frame1.empty());
  auto j = nlohmann::json::parse(manifest);
  const std::string state = j.at("state_file");
  // A manifest without its state file entry (found by review: it escaped as a bare json error).
  j.erase("state_file");
  dir.write("out/manifest.json", j.dump());
  auto r = dir.run("simulate s.json --resume --out out");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("manifest.json"), std::string::npos) << r.err;
  // A truncated state file.
  dir.write("out/manifest.json", manifest);
  const std::string bytes = CliScratch::slurp(dir / "out" / state);
  dir.write("out/" + state, bytes.substr(0, bytes.size() / 2));
  r = dir.run("simulate s.json --resume --out out");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
  // Not JSON at all.
  dir.write("out/manifest.json", "{\"frames\": [");
  r = dir.run("simulate s.json --resume --out out");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("manifest.json"), std::string::npos) << r.err;
  // The finished frame was never touched.
  EXPECT_EQ(CliScratch::slurp(dir / "out/frame_0001.obj"), frame1);
}

TEST(CliDeterminism, SimulateTwiceGivesBitwiseIdenticalFrames) {
  CliScratch dir;
  dir.write("s.json", kTinyScene);
  for (const char* out : {"a", "b"}) {
    const auto r = dir.run(std::string("simulate s.json --threads 2 --out ") + out);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  int compared = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "a")) {
    const auto name = e.path().filename().string();
    // The manifest holds wall-clock times, the lock file the run's process id.
    if (name == "manifest.json" || name == ".lock") continue;
    ASSERT_TRUE(std::filesystem::exists(dir / "b" / name)) << name;
    EXPECT_EQ(CliScratch::slurp(e.path()), CliScratch::slurp(dir / "b" / name)) << name;
    ++compared;
  }
  EXPECT_GE(compared, 4) << "frames 0..3 and the state file";
}

}  // namespace
}  // namespace clothcd
