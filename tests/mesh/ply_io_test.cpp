// PLY reader: the three encodings with mixed property types, every rejected input class (each
// naming the file and the line or element), and write/read round trips for both formats.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "clothcd/mesh/io.hpp"
#include "io_test_support.hpp"
#include "support/file_size_limit.hpp"

namespace clothcd {
namespace {

using test::expect_input_error;
using test::ScratchDir;

enum class Enc { Ascii, Little, Big };

const char* format_name(Enc e) {
  return e == Enc::Ascii    ? "ascii"
         : e == Enc::Little ? "binary_little_endian"
                            : "binary_big_endian";
}

// Appends values in one encoding; ascii values are separated by spaces, `end_item` ends a line.
class PlyBody {
 public:
  explicit PlyBody(Enc enc) : enc_(enc) {}
  template <class T>
  PlyBody& put(T value) {
    if (enc_ == Enc::Ascii) {
      if constexpr (sizeof(T) == 1) {
        bytes_ += std::to_string(static_cast<int>(value)) + " ";
      } else if constexpr (std::is_floating_point_v<T>) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.17g ", static_cast<double>(value));
        bytes_ += buf;
      } else {
        bytes_ += std::to_string(value) + " ";
      }
      return *this;
    }
    char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    const bool big = enc_ == Enc::Big;
    if (big != (std::endian::native == std::endian::big)) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i)
        std::swap(b[i], b[sizeof(T) - 1 - i]);
    }
    bytes_.append(b, sizeof(T));
    return *this;
  }
  PlyBody& end_item() {
    if (enc_ == Enc::Ascii) bytes_ += "\n";
    return *this;
  }
  [[nodiscard]] const std::string& bytes() const { return bytes_; }

 private:
  Enc enc_;
  std::string bytes_;
};

// A unit square (4 vertices, a quad and a triangle) with properties the reader must skip: a
// normal, a uchar colour, a vertex list property, a per-face int, and an extra element.
std::string mixed_ply(Enc enc) {
  std::string header = std::string("ply\nformat ") + format_name(enc) +
                       " 1.0\ncomment test\nobj_info nothing\n"
                       "element vertex 4\nproperty double x\nproperty uchar red\n"
                       "property float y\nproperty list uchar short junk\nproperty double z\n"
                       "property float nx\n"
                       "element face 2\nproperty int flags\n"
                       "property list ushort uint vertex_indices\nproperty float quality\n"
                       "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
                       "end_header\n";
  PlyBody b(enc);
  const double xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int v = 0; v < 4; ++v) {
    b.put(xy[v][0]).put(std::uint8_t{200}).put(static_cast<float>(xy[v][1]));
    b.put(static_cast<std::uint8_t>(v % 3));
    for (int j = 0; j < v % 3; ++j)
      b.put(static_cast<std::int16_t>(-j));
    b.put(0.5 * v).put(1.0f).end_item();
  }
  b.put(std::int32_t{7}).put(std::uint16_t{4});
  for (std::uint32_t i : {0u, 1u, 2u, 3u})
    b.put(i);
  b.put(0.25f).end_item();
  b.put(std::int32_t{-7}).put(std::uint16_t{3});
  for (std::uint32_t i : {3u, 2u, 1u})
    b.put(i);
  b.put(0.5f).end_item();
  b.put(std::int32_t{0}).put(std::int32_t{1}).end_item();
  return header + b.bytes();
}

class PlyEncodings : public ::testing::TestWithParam<Enc> {};

TEST_P(PlyEncodings, ReadsMixedPropertiesAndSkipsTheRest) {
  ScratchDir dir;
  const auto p = dir.file("mixed.ply", mixed_ply(GetParam()));
  const TriangleMesh m = read_ply(p);
  ASSERT_EQ(m.num_vertices(), 4);
  for (int v = 0; v < 4; ++v)
    EXPECT_EQ(m.vertices[v].z(), 0.5 * v) << v;
  EXPECT_EQ(m.vertices[2], Eigen::Vector3d(1, 1, 1.0));
  EXPECT_EQ(m.faces, (std::vector<Face>{{0, 1, 2}, {0, 2, 3}, {3, 2, 1}}));
}

TEST_P(PlyEncodings, TruncatedBody) {
  ScratchDir dir;
  std::string bytes = mixed_ply(GetParam());
  bytes.resize(bytes.size() - 12);
  const auto p = dir.file("cut.ply", bytes);
  // Either the size check or the read notices; both name the file.
  expect_input_error([&] { (void)read_ply(p); }, {"cut.ply"});
}

TEST_P(PlyEncodings, TrailingDataMeansWrongCounts) {
  ScratchDir dir;
  std::string bytes = mixed_ply(GetParam());
  bytes += GetParam() == Enc::Ascii ? "5 6\n" : std::string(8, '\0');
  const auto p = dir.file("long.ply", bytes);
  expect_input_error([&] { (void)read_ply(p); }, {"long.ply", "counts do not match"});
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PlyEncodings,
                         ::testing::Values(Enc::Ascii, Enc::Little, Enc::Big));

// A triangle with one face whose index list comes from `indices`.
std::string triangle_ply(Enc enc, std::initializer_list<std::int32_t> indices, float y1 = 0.0f,
                         const char* index_type = "int") {
  std::string header = std::string("ply\nformat ") + format_name(enc) +
                       " 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 1\nproperty list uchar " +
                       index_type + " vertex_indices\nend_header\n";
  PlyBody b(enc);
  b.put(0.0f).put(0.0f).put(0.0f).end_item();
  b.put(1.0f).put(y1).put(0.0f).end_item();
  b.put(0.0f).put(1.0f).put(0.0f).end_item();
  b.put(static_cast<std::uint8_t>(indices.size()));
  for (auto i : indices)
    b.put(i);
  b.end_item();
  return header + b.bytes();
}

TEST(PlyReadErrors, MissingFile) {
  ScratchDir dir;
  expect_input_error([&] { (void)read_ply(dir.path() / "gone.ply"); }, {"gone.ply", "no such"});
}

TEST(PlyReadErrors, EmptyFile) {
  ScratchDir dir;
  const auto p = dir.file("empty.ply", "");
  expect_input_error([&] { (void)read_ply(p); }, {"empty.ply:1:"});
}

TEST(PlyReadErrors, NotAPlyFile) {
  ScratchDir dir;
  const auto p = dir.file("obj.ply", "v 0 0 0\nend_header\n");
  expect_input_error([&] { (void)read_ply(p); }, {"obj.ply:1:", "'ply'"});
}

TEST(PlyReadErrors, UnknownFormat) {
  ScratchDir dir;
  const auto p = dir.file("fmt.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n");
  expect_input_error([&] { (void)read_ply(p); }, {"fmt.ply:2:", "binary_middle_endian"});
}

TEST(PlyReadErrors, MissingFormatLine) {
  ScratchDir dir;
  const auto p = dir.file("nofmt.ply", "ply\nelement vertex 0\nend_header\n");
  expect_input_error([&] { (void)read_ply(p); }, {"nofmt.ply", "format"});
}

TEST(PlyReadErrors, NoEndHeader) {
  ScratchDir dir;
  const auto p = dir.file("open.ply", "ply\nformat ascii 1.0\nelement vertex 3\n");
  expect_input_error([&] { (void)read_ply(p); }, {"open.ply", "end_header"});
}

TEST(PlyReadErrors, UnknownPropertyType) {
  ScratchDir dir;
  const auto p = dir.file("t.ply",
                          "ply\nformat ascii 1.0\nelement vertex 1\n"
                          "property quad x\nend_header\n");
  expect_input_error([&] { (void)read_ply(p); }, {"t.ply:4:", "'quad'"});
}

TEST(PlyReadErrors, PropertyBeforeElement) {
  ScratchDir dir;
  const auto p = dir.file("t.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n");
  expect_input_error([&] { (void)read_ply(p); }, {"t.ply:3:", "before any element"});
}

TEST(PlyReadErrors, UnknownHeaderKeyword) {
  ScratchDir dir;
  const auto p = dir.file("t.ply", "ply\nformat ascii 1.0\nbogus line\nend_header\n");
  expect_input_error([&] { (void)read_ply(p); }, {"t.ply:3:", "'bogus'"});
}

TEST(PlyReadErrors, NonNumericCount) {
  ScratchDir dir;
  const auto p = dir.file("t.ply", "ply\nformat ascii 1.0\nelement vertex -3\nend_header\n");
  expect_input_error([&] { (void)read_ply(p); }, {"t.ply:3:", "count"});
}

TEST(PlyReadErrors, AbsurdHeaderCount) {
  // Claims 10^15 vertices in a file of a few bytes: rejected before any allocation.
  for (Enc enc : {Enc::Ascii, Enc::Little, Enc::Big}) {
    ScratchDir dir;
    const auto p = dir.file("huge.ply", std::string("ply\nformat ") + format_name(enc) +
                                            " 1.0\nelement vertex 1000000000000000\n"
                                            "property float x\nproperty float y\n"
                                            "property float z\nelement face 1\n"
                                            "property list uchar int vertex_indices\n"
                                            "end_header\n0 0 0\n");
    expect_input_error([&] { (void)read_ply(p); }, {"huge.ply", "1000000000000000", "vertex"});
  }
}

TEST(PlyReadErrors, CountsBeyondIntIndices) {
  ScratchDir dir;
  const auto p = dir.file("wide.ply",
                          "ply\nformat binary_little_endian 1.0\n"
                          "element vertex 3000000000\nproperty uchar x\n"
                          "element face 0\nproperty list uchar int vertex_indices\n"
                          "end_header\n");
  expect_input_error([&] { (void)read_ply(p); }, {"wide.ply"});
}

TEST(PlyReadErrors, NoFaceElement) {
  ScratchDir dir;
  const auto p = dir.file("pts.ply",
                          "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n0 0 0\n");
  expect_input_error([&] { (void)read_ply(p); }, {"pts.ply", "'face'"});
}

TEST(PlyReadErrors, ZeroFaces) {
  ScratchDir dir;
  const auto p = dir.file("nof.ply",
                          "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                          "property float y\nproperty float z\nelement face 0\n"
                          "property list uchar int vertex_indices\nend_header\n0 0 0\n");
  expect_input_error([&] { (void)read_ply(p); }, {"nof.ply", "no faces"});
}

TEST(PlyReadErrors, MissingCoordinate) {
  ScratchDir dir;
  const auto p = dir.file("xy.ply",
                          "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                          "property float y\nelement face 0\n"
                          "property list uchar int vertex_indices\nend_header\n0 0\n");
  expect_input_error([&] { (void)read_ply(p); }, {"xy.ply", "x, y and z"});
}

TEST(PlyReadErrors, FloatIndexType) {
  ScratchDir dir;
  const auto p = dir.file("fi.ply", triangle_ply(Enc::Ascii, {0, 1, 2}, 0.0f, "float"));
  expect_input_error([&] { (void)read_ply(p); }, {"fi.ply", "integer"});
}

TEST(PlyReadErrors, IndexOutOfRange) {
  for (Enc enc : {Enc::Ascii, Enc::Little, Enc::Big}) {
    ScratchDir dir;
    const auto p = dir.file("oor.ply", triangle_ply(enc, {0, 1, 3}));
    expect_input_error([&] { (void)read_ply(p); },
                       {"oor.ply", "face 0, property 'vertex_indices'", "3", "out of range"});
  }
}

TEST(PlyReadErrors, NegativeIndex) {
  for (Enc enc : {Enc::Ascii, Enc::Little, Enc::Big}) {
    ScratchDir dir;
    const auto p = dir.file("neg.ply", triangle_ply(enc, {0, -1, 2}));
    expect_input_error([&] { (void)read_ply(p); }, {"neg.ply", "face 0", "-1"});
  }
}

TEST(PlyReadErrors, RepeatedVertex) {
  ScratchDir dir;
  const auto p = dir.file("rep.ply", triangle_ply(Enc::Little, {0, 2, 2}));
  expect_input_error([&] { (void)read_ply(p); }, {"rep.ply", "face 0", "repeats vertex 2"});
}

TEST(PlyReadErrors, FaceWithTwoVertices) {
  ScratchDir dir;
  const auto p = dir.file("two.ply", triangle_ply(Enc::Big, {0, 1}));
  expect_input_error([&] { (void)read_ply(p); }, {"two.ply", "face 0", "at least 3"});
}

TEST(PlyReadErrors, NaNCoordinate) {
  for (Enc enc : {Enc::Ascii, Enc::Little, Enc::Big}) {
    ScratchDir dir;
    const auto p =
        dir.file("nan.ply", triangle_ply(enc, {0, 1, 2}, std::numeric_limits<float>::quiet_NaN()));
    expect_input_error([&] { (void)read_ply(p); }, {"nan.ply", "vertex 1", "non-finite"});
  }
}

TEST(PlyReadErrors, InfiniteCoordinate) {
  ScratchDir dir;
  const auto p = dir.file(
      "inf.ply", triangle_ply(Enc::Little, {0, 1, 2}, std::numeric_limits<float>::infinity()));
  expect_input_error([&] { (void)read_ply(p); }, {"inf.ply", "vertex 1", "non-finite"});
}

TEST(PlyReadErrors, AsciiNonNumericToken) {
  ScratchDir dir;
  std::string text = triangle_ply(Enc::Ascii, {0, 1, 2});
  text.replace(text.find("1 0 0"), 1, "one");
  const auto p = dir.file("word.ply", text);
  // Line 11 is the second vertex line (10 header lines).
  expect_input_error([&] { (void)read_ply(p); }, {"word.ply:11:", "'one'", "vertex 1"});
}

TEST(PlyReadErrors, AsciiIndexDoesNotFitType) {
  ScratchDir dir;
  std::string text = triangle_ply(Enc::Ascii, {0, 1, 2});
  text.replace(text.rfind("3 0 1 2"), 1, "300");
  const auto p = dir.file("fit.ply", text);
  expect_input_error([&] { (void)read_ply(p); }, {"fit.ply:13:", "'300'"});
}

TEST(PlyReadErrors, AsciiEndsEarly) {
  ScratchDir dir;
  std::string text = triangle_ply(Enc::Ascii, {0, 1, 2});
  text.resize(text.rfind("3 0 1 2") + 5);
  const auto p = dir.file("early.ply", text);
  expect_input_error([&] { (void)read_ply(p); }, {"early.ply", "ends early"});
}

TEST(PlyReadErrors, BinaryListLengthPastEnd) {
  // The count byte claims 200 indices: the read stops at the end of the data.
  ScratchDir dir;
  std::string bytes = triangle_ply(Enc::Little, {0, 1, 2});
  bytes[bytes.size() - 13] = static_cast<char>(200);
  const auto p = dir.file("list.ply", bytes);
  expect_input_error([&] { (void)read_ply(p); },
                     {"list.ply", "face 0, property 'vertex_indices'", "truncated"});
}

TEST(PlyReadErrors, ShortAndUcharIndexTypes) {
  ScratchDir dir;
  for (const char* type : {"uchar", "ushort", "uint", "short", "char"}) {
    std::string header = std::string("ply\nformat binary_big_endian 1.0\nelement vertex 3\n") +
                         "property float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uint " +
                         type + " vertex_indices\nend_header\n";
    PlyBody b(Enc::Big);
    for (int i = 0; i < 9; ++i)
      b.put(static_cast<float>(i));
    b.put(std::uint32_t{3});
    for (int i : {2, 0, 1}) {
      if (std::string(type) == "uchar") b.put(static_cast<std::uint8_t>(i));
      if (std::string(type) == "char") b.put(static_cast<std::int8_t>(i));
      if (std::string(type) == "ushort") b.put(static_cast<std::uint16_t>(i));
      if (std::string(type) == "short") b.put(static_cast<std::int16_t>(i));
      if (std::string(type) == "uint") b.put(static_cast<std::uint32_t>(i));
    }
    const auto p = dir.file(std::string("t_") + type + ".ply", header + b.bytes());
    const TriangleMesh m = read_ply(p);
    EXPECT_EQ(m.faces, (std::vector<Face>{{2, 0, 1}})) << type;
    EXPECT_EQ(m.vertices[2], Eigen::Vector3d(6, 7, 8)) << type;
  }
}

TriangleMesh random_mesh(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> exponent(-12, 12), unit(-1, 1);
  TriangleMesh m;
  const int nv = 3 + static_cast<int>(rng() % 50);
  for (int i = 0; i < nv; ++i) {
    // Log-uniform magnitudes so the shortest-decimal printing is exercised across scales.
    m.vertices.emplace_back(unit(rng) * std::pow(10.0, exponent(rng)),
                            unit(rng) * std::pow(10.0, exponent(rng)), unit(rng));
  }
  const int nf = 1 + static_cast<int>(rng() % 80);
  for (int f = 0; f < nf; ++f) {
    const int a = static_cast<int>(rng() % nv);
    const int b = (a + 1 + static_cast<int>(rng() % (nv - 1))) % nv;
    int c = static_cast<int>(rng() % nv);
    while (c == a || c == b)
      c = (c + 1) % nv;
    m.faces.push_back({a, b, c});
  }
  return m;
}

TEST(MeshWrite, RoundTripIsExact) {
  ScratchDir dir;
  for (std::uint32_t seed = 0; seed < 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const TriangleMesh m = random_mesh(seed);
    write_mesh(dir.path() / "m.obj", m);
    write_mesh(dir.path() / "m.ply", m);
    EXPECT_EQ(read_mesh(dir.path() / "m.obj"), m);
    EXPECT_EQ(read_mesh(dir.path() / "m.ply"), m);
  }
  // Only the two targets remain: no temporary files left behind.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    ++files;
  }
  EXPECT_EQ(files, 2);
}

TEST(MeshWrite, OverwritesAtomically) {
  ScratchDir dir;
  const auto p = dir.path() / "m.ply";
  write_ply(p, random_mesh(1));
  write_ply(p, random_mesh(2));
  EXPECT_EQ(read_ply(p), random_mesh(2));
}

TEST(MeshWriteErrors, MissingFolder) {
  ScratchDir dir;
  const auto p = dir.path() / "no" / "such" / "m.obj";
  expect_input_error([&] { write_obj(p, random_mesh(0)); }, {"m.obj", "cannot write"});
  EXPECT_FALSE(std::filesystem::exists(p.parent_path()));
}

TEST(MeshWriteErrors, TargetIsAFolder) {
  ScratchDir dir;
  std::filesystem::create_directory(dir.path() / "d.ply");
  expect_input_error([&] { write_ply(dir.path() / "d.ply", random_mesh(0)); }, {"directory"});
}

TEST(MeshWriteErrors, InvalidMeshIsNotWritten) {
  ScratchDir dir;
  TriangleMesh m = random_mesh(3);
  m.faces.push_back({0, 1, m.num_vertices()});
  expect_input_error([&] { write_obj(dir.path() / "bad.obj", m); }, {"bad.obj", "out of range"});
  m.faces.pop_back();
  m.vertices[1].y() = std::numeric_limits<double>::quiet_NaN();
  expect_input_error([&] { write_ply(dir.path() / "bad.ply", m); }, {"bad.ply", "vertex 1"});
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(MeshWriteErrors, DiskFull) {
  // A 64 KiB file-size limit stands in for a full disk (see support/file_size_limit.hpp for why
  // not /dev/full): the write fails, the message says so, the old target survives and no
  // temporary file is left.
  ScratchDir dir;
  TriangleMesh big;
  const int n = 60;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i)
      big.vertices.emplace_back(i / 3.0, j / 7.0, 0.1 * i * j);
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      big.faces.push_back({a, a + 1, a + n + 2});
      big.faces.push_back({a, a + n + 2, a + n + 1});
    }
  }
  const TriangleMesh small = random_mesh(1);
  for (const char* name : {"m.obj", "m.ply"}) {
    const auto target = dir.path() / name;
    write_mesh(target, small);
    {
      test::FileSizeLimit full(64 * 1024);
      ASSERT_TRUE(full.active());
      expect_input_error([&] { write_mesh(target, big); }, {name, "write failed"});
    }
    EXPECT_EQ(read_mesh(target), small);
  }
  int files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path()))
    ++files;
  EXPECT_EQ(files, 2);
}

TEST(FramePair, SameTopologyPasses) {
  TriangleMesh a = random_mesh(4), b = a;
  for (auto& v : b.vertices)
    v.x() += 1.0;
  EXPECT_NO_THROW(check_same_topology(a, "f92.ply", b, "f93.ply"));
}

TEST(FramePair, DifferentVertexCount) {
  TriangleMesh a = random_mesh(4), b = a;
  b.vertices.emplace_back(0, 0, 0);
  expect_input_error([&] { check_same_topology(a, "f92.ply", b, "f93.ply"); },
                     {"f92.ply", "f93.ply", "vertices"});
}

TEST(FramePair, DifferentFaces) {
  TriangleMesh a = random_mesh(4), b = a;
  std::swap(b.faces[0][0], b.faces[0][1]);
  expect_input_error([&] { check_same_topology(a, "f92.ply", b, "f93.ply"); },
                     {"f92.ply", "f93.ply", "face 0"});
  b = a;
  b.faces.pop_back();
  expect_input_error([&] { check_same_topology(a, "a.obj", b, "b.obj"); }, {"a.obj", "b.obj"});
}

}  // namespace
}  // namespace clothcd
