#pragma once
// The two-mesh results of per-thread buffers, gathered and sorted: PairDetector's and its oracle's
// (any buffer with FeatureCounters `c` and collision lists `ab`, `ba`, `ee`).

#include <algorithm>

#include "clothcd/detect/detector.hpp"
#include "detect/narrow.hpp"

namespace clothcd::detail {

template <class Locals>
PairDetectResult collect_pair_results(const Locals& locals) {
  PairDetectResult res;
  for (const auto& l : locals) {
    l.c.add_to(res.stats);
    res.vf_a_on_b.insert(res.vf_a_on_b.end(), l.ab.begin(), l.ab.end());
    res.vf_b_on_a.insert(res.vf_b_on_a.end(), l.ba.begin(), l.ba.end());
    res.ee.insert(res.ee.end(), l.ee.begin(), l.ee.end());
  }
  std::sort(res.vf_a_on_b.begin(), res.vf_a_on_b.end(), vf_less);
  std::sort(res.vf_b_on_a.begin(), res.vf_b_on_a.end(), vf_less);
  std::sort(res.ee.begin(), res.ee.end(), ee_less);
  res.stats.vf_collisions = res.vf_a_on_b.size() + res.vf_b_on_a.size();
  res.stats.ee_collisions = res.ee.size();
  return res;
}

}  // namespace clothcd::detail
