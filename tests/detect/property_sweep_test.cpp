// The property tests of property_detect_test.cpp over many more and larger seeded scenes (label
// slow: minutes). A failure names its seed; rerun one with --gtest_filter and the seed range
// narrowed in the source.

#include <gtest/gtest.h>

#include <string>

#include "property_scenes.hpp"

namespace clothcd {
namespace {

using namespace clothcd::test;

// (first seed, last seed, scene size): larger scenes have more cells, soup and degeneracies.
struct Sweep {
  std::uint64_t first, last;
  int size;
};
constexpr Sweep kThin[] = {{100, 599, 1}, {600, 679, 3}};
constexpr Sweep kThick[] = {{100, 111, 0}};  // thick kernels: ~10 s a scene

TEST(DetectPropertySweep, SelfDetectEqualsBruteForce) {
  for (const Sweep& w : kThin) {
    for (std::uint64_t seed = w.first; seed <= w.last; ++seed) {
      const RandomScene s = random_scene(seed, w.size);
      SCOPED_TRACE("seed " + std::to_string(seed) + " size " + std::to_string(w.size) + ": " +
                   s.describe());
      check_self_detect(s, seed, 0.0);
    }
  }
}

TEST(DetectPropertySweep, SelfDetectWithThicknessEqualsBruteForce) {
  for (const Sweep& w : kThick) {
    for (std::uint64_t seed = w.first; seed <= w.last; ++seed) {
      const RandomScene s = random_scene(seed, w.size);
      SCOPED_TRACE("seed " + std::to_string(seed) + " size " + std::to_string(w.size) + ": " +
                   s.describe());
      check_self_detect(s, seed, kThickness);
    }
  }
}

TEST(DetectPropertySweep, ProximityEqualsBruteForce) {
  for (const Sweep& w : kThin) {
    for (std::uint64_t seed = w.first; seed <= w.last; ++seed) {
      const RandomScene s = random_scene(seed, w.size);
      SCOPED_TRACE("seed " + std::to_string(seed) + " size " + std::to_string(w.size) + ": " +
                   s.describe());
      check_proximity(s, seed);
    }
  }
}

TEST(DetectPropertySweep, PairDetectEqualsBruteForce) {
  for (const Sweep& w : kThin) {
    for (std::uint64_t seed = w.first; seed <= w.last; ++seed) {
      const RandomScene a = random_scene(seed, w.size);
      const RandomScene b = partner(a, seed + 100000, w.size);
      SCOPED_TRACE("seed " + std::to_string(seed) + " size " + std::to_string(w.size) + ": " +
                   a.describe());
      check_pair_detect(a, b, 0.0);
    }
  }
  for (const Sweep& w : kThick) {
    for (std::uint64_t seed = w.first; seed <= w.last; ++seed) {
      const RandomScene a = random_scene(seed, w.size);
      const RandomScene b = partner(a, seed + 100000, w.size);
      SCOPED_TRACE("thick seed " + std::to_string(seed) + " size " + std::to_string(w.size) + ": " +
                   a.describe());
      check_pair_detect(a, b, 0.1 * kThickness);
    }
  }
}

}  // namespace
}  // namespace clothcd
