// `clothcd view`: the page of a small simulation holds every frame (to within the quantisation),
// the body, the rest shape and contact flags equal to a brute-force distance check; the page of a
// detection step lists exactly the result's hits; bad input exits non-zero with the file and
// what was expected, and leaves no page (an older one unchanged).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../reliability/cli_runner.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/topology.hpp"
#include "page_reader.hpp"

namespace clothcd {
namespace {

using test::CliScratch;
using Vec3 = Eigen::Vector3d;

// A sheet falling onto a sphere: contact with the body within three frames.
const char* kScene = R"({"name": "drop", "frames": 3, "frame_dt": 0.04,
 "cloth": {"grid": {"origin": [-0.3, 0.205, -0.3], "u": [0.6, 0, 0], "v": [0, 0, 0.6],
                    "resolution": [12, 12]}},
 "body": {"type": "sphere", "center": [0, 0, 0], "radius": 0.2, "subdivisions": 2},
 "collisions": {"self": true, "body": true, "thickness": 0.01}})";

bool touches(const std::vector<int>& a, const std::vector<int>& b) {
  for (int x : a)
    if (std::find(b.begin(), b.end(), x) != b.end()) return true;
  return false;
}

// Cloth vertices within h of the body or of a cloth feature they share no vertex with, by testing
// every vertex-face and edge-edge pair (the rule of the page's contact colouring).
std::vector<bool> brute_force_contact(const TriangleMesh& cloth, const std::vector<Vec3>& body,
                                      const std::vector<Face>& body_faces, double h) {
  const int n = static_cast<int>(cloth.vertices.size());
  std::vector<bool> in(n, false);
  const Topology topo(cloth.faces, n);
  const Topology btopo(body_faces, static_cast<int>(body.size()));
  const auto& x = cloth.vertices;
  for (int v = 0; v < n; ++v) {
    for (const Face& f : cloth.faces) {
      if (touches({v}, {f[0], f[1], f[2]})) continue;
      if (point_triangle_proximity(x[v], x[f[0]], x[f[1]], x[f[2]]).distance < h) {
        in[v] = true;
        for (int w : f)
          in[w] = true;
      }
    }
    for (const Face& f : body_faces) {
      if (point_triangle_proximity(x[v], body[f[0]], body[f[1]], body[f[2]]).distance < h)
        in[v] = true;
    }
  }
  for (std::size_t b = 0; b < body.size(); ++b) {
    for (const Face& f : cloth.faces) {
      if (point_triangle_proximity(body[b], x[f[0]], x[f[1]], x[f[2]]).distance < h)
        for (int w : f)
          in[w] = true;
    }
  }
  const auto& edges = topo.edges();
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const auto& e = edges[i];
    for (std::size_t j = i + 1; j < edges.size(); ++j) {
      const auto& g = edges[j];
      if (touches({e[0], e[1]}, {g[0], g[1]})) continue;
      if (edge_edge_proximity(x[e[0]], x[e[1]], x[g[0]], x[g[1]]).distance < h) {
        for (int w : {e[0], e[1], g[0], g[1]})
          in[w] = true;
      }
    }
    for (const auto& g : btopo.edges()) {
      if (edge_edge_proximity(x[e[0]], x[e[1]], body[g[0]], body[g[1]]).distance < h)
        in[e[0]] = in[e[1]] = true;
    }
  }
  return in;
}

TEST(ViewCli, SimulationPageHoldsFramesBodyRestAndContact) {
  CliScratch dir;
  dir.write("drop.json", kScene);
  auto r = dir.run("simulate drop.json --out run --frames 3 --threads 1");
  ASSERT_EQ(r.code, 0) << r.err;
  r = dir.run("view run --out page.html");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("4 frames, body, strain, contact"), std::string::npos) << r.out;
  const test::PageData page = test::read_page(CliScratch::slurp(dir / "page.html"));
  const auto& m = page.meta;
  EXPECT_EQ(m.at("kind"), "sequence");
  ASSERT_EQ(m.at("frames").size(), 4u);
  const nlohmann::json manifest =
      nlohmann::json::parse(CliScratch::slurp(dir / "run/manifest.json"));
  EXPECT_EQ(m.at("frames")[2].at("ccd_hits"), manifest.at("frames")[1].at("ccd_hits"));
  EXPECT_EQ(m.at("frames")[3].at("max_stretch"), manifest.at("frames")[2].at("max_stretch"));
  EXPECT_TRUE(m.at("strain").get<bool>());
  EXPECT_EQ(m.at("contact_distance").get<double>(), 0.01);

  const auto& cm = m.at("meshes").at("cloth");
  const int n = cm.at("vertices").get<int>();
  ASSERT_EQ(n, 169);
  const auto cloth = page.frames("cloth");
  const auto faces = page.array<std::uint32_t>("cloth_faces");
  const auto bits = page.array<std::uint8_t>("contact");
  const auto rest = page.array<float>("rest");
  ASSERT_EQ(rest.size(), faces.size() / 3 * 4);
  const auto& bm = m.at("meshes").at("body");
  const auto body_faces_flat = page.array<std::uint32_t>("body_faces");
  std::vector<Face> body_faces;
  for (std::size_t i = 0; i < body_faces_flat.size(); i += 3) {
    body_faces.push_back({static_cast<int>(body_faces_flat[i]),
                          static_cast<int>(body_faces_flat[i + 1]),
                          static_cast<int>(body_faces_flat[i + 2])});
  }
  const auto bodies = page.frames("body");
  ASSERT_EQ(cloth.size(), 4u);
  ASSERT_EQ(bodies.size(), 4u);
  int contact_frames = 0;
  for (int k = 0; k < 4; ++k) {
    const TriangleMesh frame = read_mesh(dir / ("run/frame_000" + std::to_string(k) + ".obj"));
    ASSERT_EQ(faces.size(), frame.faces.size() * 3);
    for (int i = 0; i < n * 3; ++i) {
      const double step = cm.at("step")[i % 3].get<double>();
      EXPECT_NEAR(cloth[k][i / 3][i % 3], frame.vertices[i / 3][i % 3], 0.5 * step * (1 + 1e-9))
          << k << " " << i;
    }
    const std::vector<Vec3>& body = bodies[k];
    EXPECT_EQ(static_cast<int>(body.size()), bm.at("vertices").get<int>());
    // The flags come from the exact frame; the oracle's body from the page (to a quantum, far
    // below the contact distance, so only a pair within a quantum of h could differ: none here).
    const std::vector<bool> want = brute_force_contact(frame, body, body_faces, 0.01);
    const std::size_t row = (n + 7) / 8;
    int flagged = 0;
    for (int v = 0; v < n; ++v) {
      const bool got = (bits[k * row + v / 8] >> (v % 8)) & 1;
      EXPECT_EQ(got, want[v]) << "frame " << k << " vertex " << v;
      flagged += got;
    }
    contact_frames += flagged > 0;
  }
  EXPECT_GT(contact_frames, 0) << "the sheet never came near the sphere: the test checks nothing";
}

// A run whose scene file is gone or no longer reads (data moved) still gets a page: the cloth
// alone, without strain colouring, and a note saying why.
TEST(ViewCli, WithoutItsSceneARunShowsTheClothAlone) {
  CliScratch dir;
  dir.write("drop.json", kScene);
  ASSERT_EQ(dir.run("simulate drop.json --out run --frames 1 --threads 1").code, 0);
  dir.write("drop.json", "{\"name\": ");
  const auto r = dir.run("view run --out page.html");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("cannot read the scene"), std::string::npos) << r.err;
  const test::PageData page = test::read_page(CliScratch::slurp(dir / "page.html"));
  EXPECT_FALSE(page.meta.at("meshes").contains("body"));
  EXPECT_FALSE(page.meta.at("strain").get<bool>());
  EXPECT_TRUE(page.meta.at("contact").get<bool>());
  EXPECT_EQ(page.frames("cloth").size(), 2u);
  ASSERT_EQ(page.meta.at("notes").size(), 1u);
}

TEST(ViewCli, DetectionPageListsTheResultsHits) {
  CliScratch dir;
  // Two triangles; the lone vertex 3 passes through triangle 0-1-2 during the step.
  dir.write("a.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.2 0.2 0.5\nv 1.2 0.2 0.5\nv 0.2 1.2 0.5\n"
            "f 1 2 3\nf 4 5 6\n");
  dir.write("b.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.2 0.2 -0.5\nv 1.2 0.2 -0.5\nv 0.2 1.2 -0.5\n"
            "f 1 2 3\nf 4 5 6\n");
  auto r = dir.run("detect --t0 a.obj --t1 b.obj --json r.json");
  ASSERT_EQ(r.code, 0) << r.err;
  r = dir.run("view --t0 a.obj --t1 b.obj --json r.json --out page.html");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json result = nlohmann::json::parse(CliScratch::slurp(dir / "r.json"));
  const test::PageData page = test::read_page(CliScratch::slurp(dir / "page.html"));
  const auto kind = page.array<std::uint8_t>("hit_kind");
  const auto verts = page.array<std::int32_t>("hit_vertices");
  const auto toi = page.array<float>("hit_toi");
  const std::size_t nvf = result.at("vf").size(), nee = result.at("ee").size();
  ASSERT_GT(nvf, 0u);
  ASSERT_EQ(kind.size(), nvf + nee);
  for (std::size_t i = 0; i < nvf; ++i) {
    const auto& e = result.at("vf")[i];
    EXPECT_EQ(kind[i], 0);
    EXPECT_EQ(verts[4 * i], e.at("vertex").get<int>());
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(verts[4 * i + 1 + k], e.at("face")[k].get<int>());
    EXPECT_FLOAT_EQ(toi[i], e.at("toi").get<float>());
  }
  for (std::size_t i = 0; i < nee; ++i) {
    const auto& e = result.at("ee")[i];
    EXPECT_EQ(kind[nvf + i], 1);
    EXPECT_EQ(verts[4 * (nvf + i)], e.at("edge_a")[0].get<int>());
    EXPECT_EQ(verts[4 * (nvf + i) + 3], e.at("edge_b")[1].get<int>());
  }
  // Both triangles take part in a hit.
  const auto flags = page.array<std::uint8_t>("hit_faces");
  ASSERT_EQ(flags.size(), 2u);
  EXPECT_NE(flags[0], 0);
  EXPECT_NE(flags[1], 0);
  EXPECT_EQ(page.meta.at("stats").at("vf_collisions").get<std::size_t>(), nvf);
}

struct BadCase {
  const char* name;
  const char* args;
  const char* message;
};

TEST(ViewCli, BadInputExitsNonZeroAndLeavesNoPage) {
  CliScratch dir;
  dir.write("drop.json", kScene);
  ASSERT_EQ(dir.run("simulate drop.json --out run --frames 2 --threads 1").code, 0);
  std::filesystem::copy(dir / "run", dir / "nomanifest", std::filesystem::copy_options::recursive);
  std::filesystem::copy(dir / "run", dir / "badjson", std::filesystem::copy_options::recursive);
  std::filesystem::copy(dir / "run", dir / "noframe", std::filesystem::copy_options::recursive);
  std::filesystem::copy(dir / "run", dir / "badframe", std::filesystem::copy_options::recursive);
  std::filesystem::remove(dir / "nomanifest/manifest.json");
  dir.write("badjson/manifest.json", "{\"complete_frames\": 2, ");
  std::filesystem::remove(dir / "noframe/frame_0001.obj");
  dir.write("badframe/frame_0002.obj", "v 0 0 0\nv 1 0 zero\nf 1 2 3\n");
  dir.write("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  dir.write("b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n");
  dir.write("far.json", R"({"ee": [], "vf": [{"face": [0, 1, 2], "toi": 0.5, "vertex": 9}]})");
  dir.write("other.json", R"({"stats": {}})");
  dir.write("broken.json", R"({"vf": [)");
  const BadCase cases[] = {
      {"no folder", "view nowhere --out page.html", "nowhere: not a folder"},
      {"no manifest", "view nomanifest --out page.html", "manifest.json: cannot open"},
      {"bad manifest", "view badjson --out page.html", "manifest.json: invalid JSON"},
      {"missing frame", "view noframe --out page.html", "frame_0001.obj: missing"},
      {"bad frame", "view badframe --out page.html", "frame_0002.obj:2:"},
      {"frame past the run", "view run --last 7 --out page.html",
       "not within the complete frames 0..2"},
      {"two modes", "view run --t0 a.obj --t1 a.obj --json far.json --out page.html", "either"},
      {"step without json", "view --t0 a.obj --t1 a.obj --out page.html",
       "needs --t0, --t1 and --json"},
      {"topology", "view --t0 a.obj --t1 b.obj --json far.json --out page.html",
       "topology differs"},
      {"vertex out of range", "view --t0 a.obj --t1 a.obj --json far.json --out page.html",
       "far.json: vf[0]: vertex 9 is not a vertex of the meshes (3 vertices)"},
      {"not a result", "view --t0 a.obj --t1 a.obj --json other.json --out page.html",
       "neither 'vf' nor 'ee'"},
      {"broken result", "view --t0 a.obj --t1 a.obj --json broken.json --out page.html",
       "broken.json: invalid JSON"},
  };
  for (const BadCase& c : cases) {
    const auto r = dir.run(c.args);
    EXPECT_EQ(r.code, 2) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "page.html")) << c.name;
  }
  // A failing run leaves an older page as it was.
  dir.write("page.html", "older page");
  EXPECT_EQ(dir.run("view noframe --out page.html").code, 2);
  EXPECT_EQ(CliScratch::slurp(dir / "page.html"), "older page");
  // An unwritable target: the reason, exit 1, nothing left beside it.
  const auto r = dir.run("view run --out missing/page.html");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("cannot write"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "missing"));
}

}  // namespace
}  // namespace clothcd
