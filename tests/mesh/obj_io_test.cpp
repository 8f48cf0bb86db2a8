// OBJ reader: accepted syntax, every rejected input class (each naming file and line), and the
// stitch lines of garment stage files.

#include <gtest/gtest.h>

#include "clothcd/mesh/io.hpp"
#include "io_test_support.hpp"

namespace clothcd {
namespace {

using test::expect_input_error;
using test::ScratchDir;

const char* kSquare = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

TEST(ObjRead, TrianglesCommentsAndIgnoredStatements) {
  ScratchDir dir;
  const auto p = dir.file("a.obj",
                          "# comment\r\nmtllib x.mtl\r\no thing\r\nv 0 0 0 # trailing\r\n"
                          "v 1 0 0\r\nv +1 1e0 0\r\nvt 0 0\r\nvn 0 0 1\r\ng g0\r\ns off\r\n"
                          "usemtl m\r\nf 1/1/1 2//1 3/1\r\nl 1 2\r\n");
  const TriangleMesh m = read_obj(p);
  ASSERT_EQ(m.num_vertices(), 3);
  EXPECT_EQ(m.vertices[2], Eigen::Vector3d(1, 1, 0));
  EXPECT_EQ(m.faces, (std::vector<Face>{{0, 1, 2}}));
}

TEST(ObjRead, PolygonsAreFannedInCornerOrder) {
  ScratchDir dir;
  const auto p = dir.file("quad.obj", std::string(kSquare) + "v 0.5 2 0\nf 1 2 3 5 4\n");
  EXPECT_EQ(read_obj(p).faces, (std::vector<Face>{{0, 1, 2}, {0, 2, 4}, {0, 4, 3}}));
}

TEST(ObjRead, RelativeAndForwardIndices) {
  ScratchDir dir;
  const auto p = dir.file("rel.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n");
  EXPECT_EQ(read_obj(p).faces, (std::vector<Face>{{0, 1, 2}, {0, 1, 2}}));
}

TEST(ObjRead, FourthCoordinateAndColoursAccepted) {
  ScratchDir dir;
  const auto p = dir.file("w.obj", "v 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(read_obj(p).num_vertices(), 3);
}

TEST(ObjRead, TextureCoordinatesPerCorner) {
  // A quad fanned into two triangles keeps each corner's texture index; a corner without one
  // gets -1, a relative one resolves like a vertex index, a forward one is checked at the end.
  ScratchDir dir;
  const auto p = dir.file("t.obj", std::string(kSquare) +
                                       "vt 0 0\nvt 1 0\nvt 1 1 0\nf 1/1 2/2 3/-2 4/4\nf 1 2 4\n"
                                       "vt 0 1\n");
  const ObjContents c = read_obj_with_stitches(p);
  ASSERT_EQ(c.texcoords.size(), 4u);
  EXPECT_EQ(c.texcoords[2], Eigen::Vector2d(1, 1));
  EXPECT_EQ(c.mesh.faces, (std::vector<Face>{{0, 1, 2}, {0, 2, 3}, {0, 1, 3}}));
  EXPECT_EQ(c.face_texcoords, (std::vector<Face>{{0, 1, 1}, {0, 1, 3}, {-1, -1, -1}}));
  EXPECT_EQ(read_obj(p), c.mesh);
}

TEST(ObjRead, VerticesOnlyReadsTheVertexLines) {
  // Faces are neither read nor needed (an animation frame after the first); vertices are
  // checked as read_obj checks them.
  ScratchDir dir;
  const auto p = dir.file("v.obj", std::string(kSquare) + "f 1 2 9\nvt x y\n  v 2 0 0\n");
  EXPECT_EQ(read_obj_vertices(p),
            (std::vector<Eigen::Vector3d>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}}));
  const auto q = dir.file("w.obj", "v 0 0 0\nv 1 x 0\n");
  expect_input_error([&] { (void)read_obj_vertices(q); }, {"w.obj:2:", "'x' is not a number"});
  expect_input_error([&] { (void)read_obj_vertices(dir.path() / "missing.obj"); }, {"missing.obj"});
}

TEST(ObjReadErrors, MissingFile) {
  ScratchDir dir;
  expect_input_error([&] { (void)read_obj(dir.path() / "nope.obj"); }, {"nope.obj", "no such"});
}

TEST(ObjReadErrors, Directory) {
  ScratchDir dir;
  expect_input_error([&] { (void)read_obj(dir.path()); }, {"directory"});
}

TEST(ObjReadErrors, EmptyFile) {
  ScratchDir dir;
  const auto p = dir.file("empty.obj", "");
  expect_input_error([&] { (void)read_obj(p); }, {"empty.obj", "no faces"});
}

TEST(ObjReadErrors, VerticesOnly) {
  ScratchDir dir;
  const auto p = dir.file("pts.obj", kSquare);
  expect_input_error([&] { (void)read_obj(p); }, {"pts.obj", "no faces"});
}

TEST(ObjReadErrors, NonNumericCoordinate) {
  ScratchDir dir;
  const auto p = dir.file("bad.obj", "v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"bad.obj:2:", "'abc'", "not a number"});
}

TEST(ObjReadErrors, CoordinateWithTrailingGarbage) {
  ScratchDir dir;
  const auto p = dir.file("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1.0.0 0\nf 1 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"bad.obj:3:", "'1.0.0'"});
}

TEST(ObjReadErrors, TooFewCoordinates) {
  ScratchDir dir;
  const auto p = dir.file("bad.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"bad.obj:2:", "expected 3"});
}

TEST(ObjReadErrors, NaNCoordinate) {
  ScratchDir dir;
  const auto p = dir.file("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"nan.obj:3:", "not finite"});
}

TEST(ObjReadErrors, InfiniteCoordinate) {
  ScratchDir dir;
  const auto p = dir.file("inf.obj", "v 0 0 0\nv -inf 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"inf.obj:2:", "not finite"});
}

TEST(ObjReadErrors, OverflowingCoordinate) {
  ScratchDir dir;
  const auto p = dir.file("big.obj", "v 0 0 1e999\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"big.obj:1:", "1e999"});
}

TEST(ObjReadErrors, IndexOutOfRange) {
  ScratchDir dir;
  const auto p = dir.file("oor.obj", std::string(kSquare) + "f 1 2 3\nf 1 2 9\n");
  expect_input_error([&] { (void)read_obj(p); }, {"oor.obj:6:", "9", "out of range"});
}

TEST(ObjReadErrors, HugeIndex) {
  ScratchDir dir;
  const auto p = dir.file("huge.obj", std::string(kSquare) + "f 1 2 99999999999999999999\n");
  expect_input_error([&] { (void)read_obj(p); }, {"huge.obj:5:"});
}

TEST(ObjReadErrors, IndexZero) {
  ScratchDir dir;
  const auto p = dir.file("zero.obj", std::string(kSquare) + "f 0 1 2\n");
  expect_input_error([&] { (void)read_obj(p); }, {"zero.obj:5:", "start at 1"});
}

TEST(ObjReadErrors, NegativeIndexBeforeFirstVertex) {
  ScratchDir dir;
  const auto p = dir.file("neg.obj", std::string(kSquare) + "f -1 -2 -7\n");
  expect_input_error([&] { (void)read_obj(p); }, {"neg.obj:5:", "-7"});
}

TEST(ObjReadErrors, NonNumericIndex) {
  ScratchDir dir;
  const auto p = dir.file("idx.obj", std::string(kSquare) + "f 1 two 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"idx.obj:5:", "'two'"});
}

TEST(ObjReadErrors, MalformedCorner) {
  ScratchDir dir;
  const auto p = dir.file("corner.obj", std::string(kSquare) + "f 1/ 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"corner.obj:5:", "'1/'"});
  const auto q = dir.file("corner2.obj", std::string(kSquare) + "f 1/1/1/1 2 3\n");
  expect_input_error([&] { (void)read_obj(q); }, {"corner2.obj:5:"});
}

TEST(ObjReadErrors, FaceWithTwoCorners) {
  ScratchDir dir;
  const auto p = dir.file("two.obj", std::string(kSquare) + "f 1 2\n");
  expect_input_error([&] { (void)read_obj(p); }, {"two.obj:5:", "at least 3"});
}

TEST(ObjReadErrors, FaceRepeatsVertex) {
  ScratchDir dir;
  const auto p = dir.file("rep.obj", std::string(kSquare) + "f 1 2 3\nf 1 2 -4\n");
  expect_input_error([&] { (void)read_obj(p); }, {"rep.obj:6:", "repeats vertex 1"});
}

TEST(ObjReadErrors, TextureCoordinates) {
  ScratchDir dir;
  auto p = dir.file("a.obj", std::string(kSquare) + "vt 0\nf 1 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"a.obj:5:", "expected 2 (u v)"});
  p = dir.file("b.obj", std::string(kSquare) + "vt 0 inf\nf 1 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"b.obj:5:", "'inf' is not finite"});
  p = dir.file("c.obj", std::string(kSquare) + "vt 0 0\nf 1/2 2/1 3/1\n");
  expect_input_error([&] { (void)read_obj(p); },
                     {"c.obj:6:", "texture index 2 is out of range: the file has 1 texture"});
  p = dir.file("d.obj", std::string(kSquare) + "f 1/-1 2 3\n");
  expect_input_error([&] { (void)read_obj(p); }, {"d.obj:5:", "relative texture index -1"});
}

TEST(ObjReadErrors, BinaryData) {
  ScratchDir dir;
  const auto p = dir.file("bin.obj", std::string("v 0 0 0\n\x01\x00\xff", 11));
  expect_input_error([&] { (void)read_obj(p); }, {"bin.obj:2:", "NUL"});
}

TEST(ObjStitches, ReadsStitchLines) {
  ScratchDir dir;
  const auto p = dir.file("stage.obj", std::string(kSquare) +
                                           "f 1 2 3\nstitch 3 0 1 0.25\nstitch 2 1 0 1\n"
                                           "seam 5\n");
  const ObjContents c = read_obj_with_stitches(p);
  EXPECT_EQ(c.stitches, (std::vector<Stitch>{{3, 0, 1, 0.25}, {2, 1, 0, 1.0}}));
  EXPECT_EQ(c.mesh.num_faces(), 1);
}

TEST(ObjStitchErrors, IndexOutOfRange) {
  ScratchDir dir;
  const auto p = dir.file("s.obj", std::string(kSquare) + "f 1 2 3\nstitch 4 0 1 0.5\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"s.obj:6:", "4", "0-based"});
}

TEST(ObjStitchErrors, NegativeIndex) {
  ScratchDir dir;
  const auto p = dir.file("s.obj", std::string(kSquare) + "f 1 2 3\nstitch 0 -1 1 0.5\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"s.obj:6:", "'-1'"});
}

TEST(ObjStitchErrors, WeightOutsideUnitInterval) {
  ScratchDir dir;
  const auto p = dir.file("s.obj", std::string(kSquare) + "f 1 2 3\nstitch 0 1 2 1.5\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"s.obj:6:", "[0, 1]"});
  const auto q = dir.file("t.obj", std::string(kSquare) + "f 1 2 3\nstitch 0 1 2 nan\n");
  expect_input_error([&] { (void)read_obj_with_stitches(q); }, {"t.obj:6:", "[0, 1]"});
}

TEST(ObjStitchErrors, WrongValueCount) {
  ScratchDir dir;
  const auto p = dir.file("s.obj", std::string(kSquare) + "f 1 2 3\nstitch 0 1 2\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"s.obj:6:", "expected 4"});
}

TEST(ObjStitchErrors, DegenerateEdge) {
  ScratchDir dir;
  const auto p = dir.file("s.obj", std::string(kSquare) + "f 1 2 3\nstitch 0 2 2 0.5\n");
  expect_input_error([&] { (void)read_obj_with_stitches(p); }, {"s.obj:6:", "repeats"});
}

TEST(MeshDispatch, UnknownExtension) {
  ScratchDir dir;
  const auto p = dir.file("mesh.stl", "solid x\n");
  expect_input_error([&] { (void)read_mesh(p); }, {"mesh.stl", ".stl", ".obj or .ply"});
  expect_input_error([&] { write_mesh(dir.path() / "out.off", TriangleMesh{}); }, {".off"});
}

TEST(MeshDispatch, ExtensionIsCaseInsensitive) {
  ScratchDir dir;
  const auto p = dir.file("UP.OBJ", std::string(kSquare) + "f 1 2 3\n");
  EXPECT_EQ(read_mesh(p).num_faces(), 1);
}

}  // namespace
}  // namespace clothcd
