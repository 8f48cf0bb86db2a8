// Readers and topology on the shared real data (skipped when absent).

#include <gtest/gtest.h>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"
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
  // simulator.md section 0: 15,656 vertices, 29,456 triangles, 851 stitches.
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

}  // namespace
}  // namespace clothcd
