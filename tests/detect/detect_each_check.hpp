#pragma once
// Equality of two detections in everything but their times: collisions (ids and times of impact,
// bit for bit) and every counter of DetectStats.

#include <gtest/gtest.h>

#include "clothcd/detect/detector.hpp"

namespace clothcd::test {

inline void expect_same_detection(const DetectResult& a, const DetectResult& b) {
  EXPECT_TRUE(a.vf == b.vf) << a.vf.size() << " vs " << b.vf.size() << " VF collisions";
  EXPECT_TRUE(a.ee == b.ee) << a.ee.size() << " vs " << b.ee.size() << " EE collisions";
  const DetectStats &x = a.stats, &y = b.stats;
  EXPECT_EQ(x.box_tests, y.box_tests);
  EXPECT_EQ(x.nodes_culled, y.nodes_culled);
  EXPECT_EQ(x.cone_tests, y.cone_tests);
  EXPECT_EQ(x.contour_tests, y.contour_tests);
  EXPECT_EQ(x.contour_fails, y.contour_fails);
  EXPECT_EQ(x.internal_nodes, y.internal_nodes);
  EXPECT_EQ(x.connected_internal_nodes, y.connected_internal_nodes);
  EXPECT_EQ(x.disk_internal_nodes, y.disk_internal_nodes);
  EXPECT_EQ(x.adjacent_pairs, y.adjacent_pairs);
  EXPECT_EQ(x.triangle_pairs, y.triangle_pairs);
  EXPECT_EQ(x.triangle_pairs_apart, y.triangle_pairs_apart);
  EXPECT_EQ(x.vf_tests, y.vf_tests);
  EXPECT_EQ(x.ee_tests, y.ee_tests);
  EXPECT_EQ(x.vf_np_culled, y.vf_np_culled);
  EXPECT_EQ(x.ee_np_culled, y.ee_np_culled);
  EXPECT_EQ(x.vf_orphans, y.vf_orphans);
  EXPECT_EQ(x.ee_orphans, y.ee_orphans);
  EXPECT_EQ(x.vf_collisions, y.vf_collisions);
  EXPECT_EQ(x.ee_collisions, y.ee_collisions);
}

}  // namespace clothcd::test
