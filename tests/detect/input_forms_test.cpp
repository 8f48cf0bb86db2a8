// Every input form of the detectors gives the same results as the column-major matrix form: spans
// of points (a std::vector, or a row-major matrix viewed in place), faces as an integer matrix;
// for detect, proximity and rebuild of both detectors. Results are compared exactly (same pairs,
// same times of impact, same distances), and against brute force for the self step.

#include <gtest/gtest.h>

#include <vector>

#include "api_scenes.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/research/oracle.hpp"
#include "clothcd/research/procedural.hpp"

namespace clothcd {
namespace {

using namespace clothcd::test;

std::vector<Eigen::Vector3d> points_of(const Positions& m) {
  std::vector<Eigen::Vector3d> p(static_cast<std::size_t>(m.rows()));
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    p[i] = m.row(i).transpose();
  return p;
}

Eigen::MatrixX3i face_matrix(const std::vector<Face>& faces) {
  Eigen::MatrixX3i f(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i)
    f.row(static_cast<Eigen::Index>(i)) << faces[i][0], faces[i][1], faces[i][2];
  return f;
}

void expect_proximity_equal(const ProximityResult& r, const ProximityResult& ref) {
  ASSERT_EQ(r.vf.size(), ref.vf.size());
  for (std::size_t i = 0; i < r.vf.size(); ++i) {
    EXPECT_EQ(r.vf[i].vertex, ref.vf[i].vertex);
    EXPECT_EQ(r.vf[i].face, ref.vf[i].face);
    EXPECT_EQ(r.vf[i].distance, ref.vf[i].distance);
  }
  ASSERT_EQ(r.ee.size(), ref.ee.size());
  for (std::size_t i = 0; i < r.ee.size(); ++i) {
    EXPECT_EQ(r.ee[i].edge_a, ref.ee[i].edge_a);
    EXPECT_EQ(r.ee[i].edge_b, ref.ee[i].edge_b);
    EXPECT_EQ(r.ee[i].distance, ref.ee[i].distance);
  }
}

TEST(InputForms, RowMajorViewReadsTheMatrixInPlace) {
  RowPositions m(4, 3);
  m.setRandom();
  const auto p = as_points(m);
  ASSERT_EQ(p.size(), 4u);
  EXPECT_EQ(static_cast<const void*>(p.data()), static_cast<const void*>(m.data()));
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(p[i], Eigen::Vector3d(m.row(i).transpose()));
}

TEST(InputForms, SelfDetectorGivesTheSameResultsForEveryForm) {
  const research::ProceduralScene s = research::crumpled_sheet(10, 3);
  DetectOptions o;
  o.culling = Culling::Sound;
  o.thickness = 1e-3;
  const Topology topo(s.faces, s.num_vertices);
  const DetectResult oracle = research::brute_force_detect(topo, s.v_t0, s.v_t1, o);
  ASSERT_GT(oracle.vf.size() + oracle.ee.size(), 0u);

  const std::vector<Eigen::Vector3d> p0 = points_of(s.v_t0), p1 = points_of(s.v_t1);
  const RowPositions r0 = s.v_t0, r1 = s.v_t1;
  SelfDetector by_matrix(s.faces, s.num_vertices, s.v_t0, o);
  SelfDetector by_span(s.faces, s.num_vertices, std::span<const Eigen::Vector3d>(p0), o);
  SelfDetector by_face_matrix(face_matrix(s.faces), s.v_t0, o);

  const DetectResult ref = by_matrix.detect(s.v_t0, s.v_t1);
  EXPECT_EQ(ref.vf, oracle.vf);
  EXPECT_EQ(ref.ee, oracle.ee);
  for (SelfDetector* det : {&by_matrix, &by_span, &by_face_matrix}) {
    const DetectResult a = det->detect(p0, p1);
    const DetectResult b = det->detect(as_points(r0), as_points(r1));
    const DetectResult c = det->detect(s.v_t0, s.v_t1);
    for (const DetectResult* r : {&a, &b, &c}) {
      EXPECT_EQ(r->vf, ref.vf);
      EXPECT_EQ(r->ee, ref.ee);
    }
  }

  const double h = 0.02;
  const ProximityResult pref = by_matrix.proximity(s.v_t1, h);
  ASSERT_GT(pref.vf.size() + pref.ee.size(), 0u);
  expect_proximity_equal(by_span.proximity(p1, h), pref);
  expect_proximity_equal(by_face_matrix.proximity(as_points(r1), h), pref);

  by_span.rebuild(std::span<const Eigen::Vector3d>(p1));
  by_matrix.rebuild(s.v_t1);
  const DetectResult after_span = by_span.detect(p0, p1);
  const DetectResult after_matrix = by_matrix.detect(s.v_t0, s.v_t1);
  EXPECT_EQ(after_span.vf, ref.vf);
  EXPECT_EQ(after_span.ee, ref.ee);
  EXPECT_EQ(after_matrix.vf, ref.vf);
  EXPECT_EQ(after_matrix.ee, ref.ee);
}

TEST(InputForms, PairDetectorGivesTheSameResultsForEveryForm) {
  const Mesh a = sheet(8);
  const Mesh b = ball(2, 0.18, {0.47, 0.52, 0.2}, {0.5, 0.49, 0.05});
  DetectOptions o;
  o.thickness = 2e-3;
  const auto a0 = points_of(a.v0), a1 = points_of(a.v1), b0 = points_of(b.v0), b1 = points_of(b.v1);
  const RowPositions ra1 = a.v1, rb1 = b.v1;
  PairDetector by_matrix(a.faces, a.nv(), a.v0, b.faces, b.nv(), b.v0, o);
  PairDetector by_span(a.faces, a.nv(), std::span<const Eigen::Vector3d>(a0), b.faces, b.nv(),
                       std::span<const Eigen::Vector3d>(b0), o);
  PairDetector by_face_matrix(face_matrix(a.faces), a.v0, face_matrix(b.faces), b.v0, o);

  const PairDetectResult ref = by_matrix.detect(a.v0, a.v1, b.v0, b.v1);
  ASSERT_GT(ref.vf_a_on_b.size() + ref.vf_b_on_a.size() + ref.ee.size(), 0u);
  const Topology ta(a.faces, a.nv()), tb(b.faces, b.nv());
  expect_pair_equal(ref, research::brute_force_detect_pair(ta, a.v0, a.v1, tb, b.v0, b.v1, o));
  for (PairDetector* det : {&by_matrix, &by_span, &by_face_matrix}) {
    expect_pair_equal(det->detect(a0, a1, b0, b1), ref);
    expect_pair_equal(det->detect(a.v0, a.v1, b.v0, b.v1), ref);
  }

  const double h = 0.03;
  const PairProximityResult pref = by_matrix.proximity(a.v1, b.v1, h);
  ASSERT_GT(pref.vf_a_on_b.size() + pref.vf_b_on_a.size() + pref.ee.size(), 0u);
  for (const PairProximityResult& r :
       {by_span.proximity(a1, b1, h),
        by_face_matrix.proximity(as_points(ra1), as_points(rb1), h)}) {
    expect_proximity_equal({r.vf_a_on_b, r.ee, 0}, {pref.vf_a_on_b, pref.ee, 0});
    expect_proximity_equal({r.vf_b_on_a, {}, 0}, {pref.vf_b_on_a, {}, 0});
  }

  by_span.rebuild(std::span<const Eigen::Vector3d>(a1), std::span<const Eigen::Vector3d>(b1));
  expect_pair_equal(by_span.detect(a0, a1, b0, b1), ref);
}

TEST(InputForms, BadSpansAreInputErrors) {
  const research::ProceduralScene s = research::crumpled_sheet(4, 1);
  std::vector<Eigen::Vector3d> p = points_of(s.v_t0);
  SelfDetector det(s.faces, s.num_vertices, s.v_t0);
  const std::vector<Eigen::Vector3d> short_list(p.begin(), p.end() - 1);
  EXPECT_THROW((void)det.detect(short_list, p), InputError);
  p[2].y() = std::numeric_limits<double>::quiet_NaN();
  try {
    (void)det.detect(points_of(s.v_t0), p);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "positions at t1: vertex 2 has a non-finite coordinate");
  }
  Eigen::MatrixX3i bad = face_matrix(s.faces);
  bad(1, 2) = s.num_vertices;
  EXPECT_THROW(SelfDetector(bad, s.v_t0), InputError);
}

}  // namespace
}  // namespace clothcd
