#pragma once
// Comparing detections in everything but their times: every counter of DetectStats, and the
// collisions (ids and times of impact, bit for bit).

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "clothcd/detect/detector.hpp"

namespace clothcd::test {

/// Every counter of a detection, times excluded, in declaration order.
inline std::vector<std::uint64_t> counters(const DetectStats& s) {
  return {s.box_tests,
          s.nodes_culled,
          s.cone_tests,
          s.contour_tests,
          s.contour_fails,
          std::uint64_t(s.internal_nodes),
          std::uint64_t(s.connected_internal_nodes),
          std::uint64_t(s.disk_internal_nodes),
          s.adjacent_pairs,
          s.triangle_pairs,
          s.triangle_pairs_apart,
          s.vf_tests,
          s.ee_tests,
          s.vf_np_culled,
          s.ee_np_culled,
          s.vf_orphans,
          s.ee_orphans,
          s.vf_collisions,
          s.ee_collisions};
}

inline void expect_same_detection(const DetectResult& a, const DetectResult& b) {
  EXPECT_TRUE(a.vf == b.vf) << a.vf.size() << " vs " << b.vf.size() << " VF collisions";
  EXPECT_TRUE(a.ee == b.ee) << a.ee.size() << " vs " << b.ee.size() << " EE collisions";
  EXPECT_EQ(counters(a.stats), counters(b.stats));
}

}  // namespace clothcd::test
