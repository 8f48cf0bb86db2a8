// The C++ detector API on bad and degenerate input: non-finite positions, wrong vertex counts and
// bad faces are InputErrors naming what is wrong; empty meshes, duplicate faces and zero-area faces
// are allowed and detected exactly like the brute-force oracle (same pair sets, finite times).

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/topology.hpp"
#include "clothcd/research/oracle.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd {
namespace {

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

void expect_contains(const std::string& msg, const std::vector<std::string>& parts) {
  for (const auto& p : parts)
    EXPECT_NE(msg.find(p), std::string::npos) << msg << " lacks " << p;
}

TEST(DetectorInput, NonFinitePositionsAreRejected) {
  const research::ProceduralScene s = research::crumpled_sheet(6, 1);
  SelfDetector det(s.faces, s.num_vertices, s.v_t0);
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity()}) {
    Positions p1 = s.v_t1;
    p1(5, 1) = bad;
    expect_contains(error_of([&] { (void)det.detect(s.v_t0, p1); }), {"t1", "vertex 5"});
    Positions p0 = s.v_t0;
    p0(0, 2) = bad;
    expect_contains(error_of([&] { (void)det.detect(p0, s.v_t1); }), {"t0", "vertex 0"});
  }
  // The detector still works after a rejected call.
  const DetectResult r = det.detect(s.v_t0, s.v_t1);
  const DetectResult ref =
      research::brute_force_detect(Topology(s.faces, s.num_vertices), s.v_t0, s.v_t1);
  EXPECT_EQ(r.vf, ref.vf);
  EXPECT_EQ(r.ee, ref.ee);
}

TEST(DetectorInput, WrongVertexCountIsRejected) {
  const research::ProceduralScene s = research::crumpled_sheet(6, 2);
  SelfDetector det(s.faces, s.num_vertices, s.v_t0);
  const Positions fewer = s.v_t1.topRows(s.num_vertices - 1);
  expect_contains(error_of([&] { (void)det.detect(s.v_t0, fewer); }),
                  {"t1", std::to_string(s.num_vertices) + " x 3"});
  const Positions two_columns = s.v_t1.leftCols(2);
  expect_contains(error_of([&] { (void)det.detect(two_columns, s.v_t1); }), {"t0", "x 2"});
  expect_contains(error_of([&] { SelfDetector bad(s.faces, s.num_vertices, fewer); }),
                  {std::to_string(s.num_vertices)});
}

TEST(DetectorInput, BadFacesAreRejected) {
  const Positions v = Positions::Random(4, 3);
  expect_contains(error_of([&] { SelfDetector d({{0, 1, 4}}, 4, v); }), {"face 0", "out of range"});
  expect_contains(error_of([&] { SelfDetector d({{0, 1, -1}}, 4, v); }), {"face 0", "-1"});
  expect_contains(error_of([&] {
                    SelfDetector d({{0, 1, 2}, {1, 3, 1}}, 4, v);
                  }),
                  {"face 1", "repeats"});
}

TEST(DetectorInput, EmptyMeshFindsNothing) {
  const Positions none(0, 3);
  SelfDetector det({}, 0, none);
  const DetectResult r = det.detect(none, none);
  EXPECT_TRUE(r.vf.empty());
  EXPECT_TRUE(r.ee.empty());
  // Vertices without faces: nothing to collide either.
  const Positions loose = Positions::Random(5, 3);
  SelfDetector det2({}, 5, loose);
  EXPECT_TRUE(det2.detect(loose, loose).vf.empty());
}

// Duplicate and zero-area faces are allowed (reported by mesh diagnostics, not rejected): the
// detector must match the oracle on them under every culling mode, with times in [0, 1].
TEST(DetectorInput, DuplicateAndDegenerateFacesMatchOracle) {
  research::ProceduralScene s = research::crumpled_sheet(8, 3);
  const int n = s.num_vertices;
  s.faces.push_back(s.faces[10]);                                       // exact duplicate
  s.faces.push_back({s.faces[20][2], s.faces[20][1], s.faces[20][0]});  // flipped duplicate
  // A zero-area face: three new vertices on one line, moving into the sheet.
  Positions v0(n + 3, 3), v1(n + 3, 3);
  v0.topRows(n) = s.v_t0;
  v1.topRows(n) = s.v_t1;
  const Eigen::RowVector3d c0 = s.v_t0.colwise().mean(), c1 = s.v_t1.colwise().mean();
  for (int k = 0; k < 3; ++k) {
    v0.row(n + k) = c0 + Eigen::RowVector3d(0.01 * k, 0.5, 0.0);
    v1.row(n + k) = c1 + Eigen::RowVector3d(0.01 * k, -0.5, 0.0);
  }
  s.faces.push_back({n, n + 1, n + 2});
  const Topology topo(s.faces, n + 3);
  const DetectResult ref = research::brute_force_detect(topo, v0, v1);
  ASSERT_GT(ref.vf.size() + ref.ee.size(), 0u);
  for (Culling c : {Culling::None, Culling::Sound}) {
    DetectOptions o;
    o.culling = c;
    SelfDetector det(s.faces, n + 3, v0, o);
    const DetectResult r = det.detect(v0, v1);
    EXPECT_EQ(r.vf, ref.vf) << static_cast<int>(c);
    EXPECT_EQ(r.ee, ref.ee) << static_cast<int>(c);
    for (const auto& x : r.vf)
      EXPECT_TRUE(x.toi >= 0.0 && x.toi <= 1.0) << x.toi;
    for (const auto& x : r.ee)
      EXPECT_TRUE(x.toi >= 0.0 && x.toi <= 1.0) << x.toi;
  }
}

}  // namespace
}  // namespace clothcd
