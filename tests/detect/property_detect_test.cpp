// Property tests of the whole detector against brute force on seeded random scenes (see
// property_scenes.hpp): scales from 1e-4 to 1e4, far from the origin, with slivers, zero-area
// triangles, duplicate vertices and non-manifold edges; every culling mode that claims exactness
// (None, Sound with each cone policy), both BVH builds, thickness 0 and > 0. A failure names its
// seed. Non-finite positions are an InputError naming the vertex. The larger sweep is
// property_sweep_test.cpp (label slow).

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "clothcd/core/error.hpp"
#include "property_scenes.hpp"

namespace clothcd {
namespace {

using namespace clothcd::test;

constexpr int kSeeds = 12;
// The thick kernels cost about a millisecond a query on these interpenetrating scenes: here two
// small scenes; property_sweep_test.cpp runs many more.
constexpr std::uint64_t kThickSeeds[] = {1, 5};

TEST(DetectProperty, SelfDetectEqualsBruteForce) {
  std::size_t found = 0;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const RandomScene s = random_scene(seed);
    SCOPED_TRACE("seed " + std::to_string(seed) + ": " + s.describe());
    found += check_self_detect(s, seed, 0.0);
  }
  EXPECT_GT(found, 0u);  // the scenes do collide
}

TEST(DetectProperty, SelfDetectWithThicknessEqualsBruteForce) {
  std::size_t found = 0;
  for (std::uint64_t seed : kThickSeeds) {
    const RandomScene s = random_scene(seed, 0);
    SCOPED_TRACE("seed " + std::to_string(seed) + " (size 0): " + s.describe());
    found += check_self_detect(s, seed, kThickness);
  }
  EXPECT_GT(found, 0u);
}

TEST(DetectProperty, ProximityEqualsBruteForce) {
  std::size_t found = 0;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const RandomScene s = random_scene(seed);
    SCOPED_TRACE("seed " + std::to_string(seed) + ": " + s.describe());
    found += check_proximity(s, seed);
  }
  EXPECT_GT(found, 0u);
}

TEST(DetectProperty, PairDetectEqualsBruteForce) {
  std::size_t found = 0;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const RandomScene a = random_scene(seed);
    const RandomScene b = partner(a, seed + 1000);
    SCOPED_TRACE("seed " + std::to_string(seed) + ": " + a.describe());
    found += check_pair_detect(a, b, 0.0);
  }
  EXPECT_GT(found, 0u);
}

TEST(DetectProperty, PairDetectWithThicknessEqualsBruteForce) {
  std::size_t found = 0;
  for (std::uint64_t seed : {std::uint64_t{1}}) {
    const RandomScene a = random_scene(seed, 0);
    const RandomScene b = partner(a, seed + 1000, 0);
    SCOPED_TRACE("seed " + std::to_string(seed) + " (size 0): " + a.describe());
    found += check_pair_detect(a, b, 0.1 * kThickness);  // fewer hits: cheaper
  }
  EXPECT_GT(found, 0u);
}

// Runs `call` and expects an InputError whose message names vertex `v`.
template <class Call>
void expect_vertex_error(Call&& call, int v, const std::string& what) {
  SCOPED_TRACE(what);
  try {
    call();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("vertex " + std::to_string(v) + " "), std::string::npos) << msg;
    EXPECT_NE(msg.find("non-finite"), std::string::npos) << msg;
  }
}

// NaN or an infinity in any position matrix of any entry point is an InputError naming the
// vertex; the detector stays usable and still equals brute force afterwards.
TEST(DetectProperty, NonFinitePositionsNameTheVertex) {
  const double bad_values[] = {std::numeric_limits<double>::quiet_NaN(),
                               std::numeric_limits<double>::infinity(),
                               -std::numeric_limits<double>::infinity()};
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const RandomScene s = random_scene(seed);
    const RandomScene b = partner(s, seed + 1000);
    SCOPED_TRACE("seed " + std::to_string(seed) + ": " + s.describe());
    const Topology topo(s.faces, s.nv());
    Rng rng(seed);
    for (double bad : bad_values) {
      const int v = rng.integer(0, s.nv() - 1), k = rng.integer(0, 2);
      Positions p = s.v1;
      p(v, k) = bad;
      SelfDetector det(s.faces, s.nv(), s.v0, {});
      expect_vertex_error([&] { SelfDetector d(s.faces, s.nv(), p, {}); }, v, "reference");
      expect_vertex_error([&] { (void)det.detect(p, s.v1); }, v, "detect t0");
      expect_vertex_error([&] { (void)det.detect(s.v0, p); }, v, "detect t1");
      expect_vertex_error([&] { (void)det.proximity(p, 0.01 * s.scale); }, v, "proximity");
      expect_vertex_error([&] { det.rebuild(p); }, v, "rebuild");
      expect_vertex_error([&] { (void)research::brute_force_detect(topo, s.v0, p); }, v, "oracle");
      expect_same(det.detect(s.v0, s.v1), research::brute_force_detect(topo, s.v0, s.v1), 1e-4);

      const int w = rng.integer(0, b.nv() - 1);
      Positions q = b.v0;
      q(w, k) = bad;
      PairDetector pd(s.faces, s.nv(), s.v0, b.faces, b.nv(), b.v0, {});
      expect_vertex_error([&] { PairDetector d(s.faces, s.nv(), p, b.faces, b.nv(), b.v0); }, v,
                          "pair reference A");
      expect_vertex_error([&] { PairDetector d(s.faces, s.nv(), s.v0, b.faces, b.nv(), q); }, w,
                          "pair reference B");
      expect_vertex_error([&] { (void)pd.detect(p, s.v1, b.v0, b.v1); }, v, "pair A t0");
      expect_vertex_error([&] { (void)pd.detect(s.v0, p, b.v0, b.v1); }, v, "pair A t1");
      expect_vertex_error([&] { (void)pd.detect(s.v0, s.v1, q, b.v1); }, w, "pair B t0");
      expect_vertex_error([&] { (void)pd.detect(s.v0, s.v1, b.v0, q); }, w, "pair B t1");
    }
  }
}

// Regression: a NaN thickness made every BVH box NaN, so that two triangles passing through each
// other gave no collision at all (and an infinite or negative one threw std::invalid_argument
// from the first kernel reached). Bad thickness and toi tolerance are an InputError naming the
// option, at construction and at set_options, for both detectors.
TEST(DetectProperty, BadThicknessOrToiToleranceIsAnInputErrorNamingTheOption) {
  const std::vector<Face> faces{{0, 1, 2}, {3, 4, 5}};
  Positions a(6, 3);
  a << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 1, 1.2, 0.2, 1, 0.2, 1.2, 1;
  Positions b = a;
  b.col(2).tail(3).setConstant(-1);  // the second triangle passes through the first
  const Topology topo(faces, 6);
  ASSERT_GT(research::brute_force_detect(topo, a, b).ee.size(), 0u);
  auto expect_option_error = [](auto&& call, const std::string& option) {
    try {
      call();
      ADD_FAILURE() << "no InputError for " << option;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(option), std::string::npos) << e.what();
    }
  };
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), -0.01}) {
    SCOPED_TRACE("value " + std::to_string(bad));
    for (int which = 0; which < 2; ++which) {
      DetectOptions o;
      (which == 0 ? o.thickness : o.toi_tolerance) = bad;
      const std::string name = which == 0 ? "thickness" : "toi tolerance";
      expect_option_error([&] { SelfDetector d(faces, 6, a, o); }, name);
      expect_option_error([&] { PairDetector d(faces, 6, a, faces, 6, a, o); }, name);
      SelfDetector det(faces, 6, a, {});
      expect_option_error([&] { det.set_options(o); }, name);
      expect_same(det.detect(a, b), research::brute_force_detect(topo, a, b),
                  1e-4);  // options unchanged
    }
  }
}

}  // namespace
}  // namespace clothcd
