// Readers and topology on the shared real data (skipped when absent).

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/sewing.hpp"
#include "clothcd/mesh/topology.hpp"
#include "support/data.hpp"

namespace clothcd {
namespace {

TEST(MeshData, ClothBallFramesShareTopology) {
  CLOTHCD_REQUIRE_DATA(f92, "cloth-ball/frames/cloth_ball92.ply");
  CLOTHCD_REQUIRE_DATA(f93, "cloth-ball/frames/cloth_ball93.ply");
  const TriangleMesh a = read_mesh(f92), b = read_mesh(f93);
  // Facts from the data's README.
  EXPECT_EQ(a.num_vertices(), 46598);
  EXPECT_EQ(a.num_faces(), 92230);
  EXPECT_NO_THROW(check_same_topology(a, f92, b, f93));
  const Topology topo(a.faces, a.num_vertices());
  EXPECT_EQ(topo.num_edges(), 138825);
  // The frames really move.
  EXPECT_NE(a.vertices, b.vertices);
}

TEST(MeshData, ClothBallFramesAgainstOtherGarment) {
  CLOTHCD_REQUIRE_DATA(f92, "cloth-ball/frames/cloth_ball92.ply");
  CLOTHCD_REQUIRE_DATA(drape, "garments/dress_knife/drape.obj");
  const TriangleMesh a = read_mesh(f92), b = read_mesh(drape);
  EXPECT_THROW(check_same_topology(a, f92, b, drape), InputError);
}

TEST(MeshData, DressStageStitches) {
  CLOTHCD_REQUIRE_DATA(stage, "garments/dress_knife/stage.obj");
  const ObjContents c = read_obj_with_stitches(stage);
  // docs/simulator.md 0: 15,656 vertices, 29,456 triangles, 851 stitches.
  EXPECT_EQ(c.mesh.num_vertices(), 15656);
  EXPECT_EQ(c.mesh.num_faces(), 29456);
  EXPECT_EQ(c.stitches.size(), 851u);
}

TEST(MeshData, DrapesHoldGarmentThenMannequin) {
  CLOTHCD_REQUIRE_DATA(dress, "garments/dress_knife/drape.obj");
  CLOTHCD_REQUIRE_DATA(multi, "garments/multilayer/drape.obj");
  CLOTHCD_REQUIRE_DATA(body, "body/wm2_15k.obj");
  const TriangleMesh d = read_mesh(dress), m = read_mesh(multi), b = read_mesh(body);
  EXPECT_EQ(d.num_vertices(), 15656 + b.num_vertices());
  EXPECT_EQ(d.num_faces(), 29456 + b.num_faces());
  EXPECT_EQ(m.num_vertices(), 30464 + b.num_vertices());
  EXPECT_EQ(m.num_faces(), 58687 + b.num_faces());
  // The garment's faces use only garment vertices.
  EXPECT_NO_THROW((void)submesh_prefix(d, 15656, 29456));
  EXPECT_NO_THROW((void)submesh_prefix(m, 30464, 58687));
}

void print(const char* what, const SewnMesh& s) {
  const SewingReport& r = s.report;
  std::printf(
      "%s: components %d -> %d, boundary edges %d -> %d, non-manifold edges %d -> %d, "
      "vertices welded %d, edges split %d, faces dropped %d\n",
      what, r.components_before, r.components_after, r.boundary_edges_before,
      r.boundary_edges_after, r.nonmanifold_edges_before, r.nonmanifold_edges_after,
      r.vertices_welded, r.edges_split, r.faces_dropped);
}

struct Garment {
  const char* path;
  int vertices, faces, panels;
  bool exactly_apart;  // no two vertices coincide within 1e-9
};

// At 0.1 mm each garment sews into one edge-connected sheet; at 1e-9 the panels stay
// apart (docs/simulator.md 0: 14 panels for the dress, 10 for the multilayer).
TEST(MeshData, GarmentsSewIntoOneSheet) {
  for (const Garment g : {Garment{"garments/dress_knife/drape.obj", 15656, 29456, 14, true},
                          Garment{"garments/multilayer/drape.obj", 30464, 58687, 10, false}}) {
    SCOPED_TRACE(g.path);
    CLOTHCD_REQUIRE_DATA(path, g.path);
    const TriangleMesh garment = submesh_prefix(read_mesh(path), g.vertices, g.faces);
    const SewnMesh exact = sew(garment, 1e-9);
    print((std::string(g.path) + " at 1e-9").c_str(), exact);
    EXPECT_EQ(exact.report.components_before, g.panels);
    if (g.exactly_apart) {
      EXPECT_EQ(exact.report.components_after, g.panels);
      EXPECT_EQ(exact.report.vertices_welded, 0);
    }
    const double tol = 1e-4;
    const SewnMesh sewn = sew(garment, tol);
    print((std::string(g.path) + " at 1e-4").c_str(), sewn);
    EXPECT_EQ(sewn.report.components_after, 1);
    // Only faces with an edge shorter than the tolerance can collapse (the dress has one such
    // 0.09 mm edge inside a panel).
    int short_edged = 0;
    for (const Face& f : garment.faces) {
      bool short_edge = false;
      for (int k = 0; k < 3; ++k) {
        short_edge |= (garment.vertices[f[k]] - garment.vertices[f[(k + 1) % 3]]).norm() <= tol;
      }
      short_edged += short_edge;
    }
    EXPECT_EQ(sewn.report.faces_dropped, short_edged);
    EXPECT_LT(sewn.report.boundary_edges_after, sewn.report.boundary_edges_before);
    // Every original vertex maps to a sewn vertex within the tolerance (up to chains).
    for (int v = 0; v < garment.num_vertices(); ++v) {
      ASSERT_LE((sewn.mesh.vertices[sewn.vertex_map[v]] - garment.vertices[v]).norm(), 1e-3);
    }
  }
}

// The dress's listed stitches, applied to its drape (same numbering as stage.obj).
TEST(MeshData, DressStitchesSewTheDrape) {
  CLOTHCD_REQUIRE_DATA(stage_path, "garments/dress_knife/stage.obj");
  CLOTHCD_REQUIRE_DATA(drape_path, "garments/dress_knife/drape.obj");
  const ObjContents stage = read_obj_with_stitches(stage_path);
  const TriangleMesh garment = submesh_prefix(read_mesh(drape_path), 15656, 29456);
  ASSERT_EQ(stage.mesh.faces, garment.faces);
  const SewnMesh sewn = sew_stitches(garment, stage.stitches);
  print("dress_knife stitches", sewn);
  EXPECT_EQ(sewn.report.components_before, 14);
  EXPECT_EQ(sewn.report.components_after, 1);
}

}  // namespace
}  // namespace clothcd
