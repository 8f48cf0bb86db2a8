#pragma once
// The narrow phase's per-thread buffers: the feature pairs and triangle pairs queued for the
// vectorised filters, their counters, and one face's feature boxes side by side.

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "ccd/batch.hpp"
#include "clothcd/bvh/aabb.hpp"
#include "clothcd/ccd/queries.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/detect/types.hpp"
#include "detect/step_positions.hpp"

namespace clothcd::detail {

/// Swept box of a feature, stored in float (half the memory traffic of the narrow phase, whose
/// box tests are memory-bound), rounded outwards so it still contains the double box.
using Box = FeatureBox;
using clothcd::overlap;

inline bool share_vertex(const Face& a, const Face& b) {
  for (int x : a) {
    if (x == b[0] || x == b[1] || x == b[2]) return true;
  }
  return false;
}

/// Per-thread counters of the feature tests.
struct FeatureCounters {
  std::uint64_t vf_tests = 0, ee_tests = 0, vf_np = 0, ee_np = 0;
  std::uint64_t triangle_pairs = 0;  // triangle pairs reaching the narrow phase
  std::uint64_t faces_apart = 0;     // ... culled whole (FacesApartBatch)

  /// Adds the feature test counters (not triangle_pairs, which callers count their own way).
  void add_to(DetectStats& s) const {
    s.vf_tests += vf_tests;
    s.ee_tests += ee_tests;
    s.vf_np_culled += vf_np;
    s.ee_np_culled += ee_np;
    s.triangle_pairs_apart += faces_apart;
  }
};

/// Feature pairs waiting for the vectorised filters (np_batch.hpp: the NP filter at zero
/// thickness, the distance filter at a thickness), which FeatureContext::queue_vf and queue_ee
/// run a batch at a time; one per thread.
struct FeatureBatch {
  static constexpr int kCapacity = ccd_detail::NpBatch::kCapacity;
  ccd_detail::NpBatch vf, ee;  // gathered positions
  std::array<std::pair<int, int>, kCapacity> vf_ids, ee_ids;
  std::array<ccd_detail::NpVerdict, kCapacity> verdict;
  std::array<ccd_detail::FastSettled, kCapacity> settled;  // ccd_detail::fast_path_settle
  std::array<double, kCapacity> toi;

  /// Queues the VF pair `ids` (vertex, face) with its 8 points (vf_points); true when full.
  bool push_vf(std::pair<int, int> ids, const std::array<const double*, 8>& points) {
    vf_ids[vf.size] = ids;
    vf.push(points);
    return vf.full();
  }
  /// Queues the EE pair `ids` with its 8 points (ee_points); true when full.
  bool push_ee(std::pair<int, int> ids, const std::array<const double*, 8>& points) {
    ee_ids[ee.size] = ids;
    ee.push(points);
    return ee.full();
  }
};

/// The query of a batch's i-th pair, read back from its gathered positions: the query that
/// was queued, bit for bit.
template <class Query>
Query query_at(const ccd_detail::NpBatch& b, int i) {
  const auto point = [&](int p) {
    return Eigen::Vector3d(b.x[3 * p][i], b.x[3 * p + 1][i], b.x[3 * p + 2][i]);
  };
  return Query{point(0), point(1), point(2), point(3), point(4), point(5), point(6), point(7)};
}

/// Triangle pairs waiting for the whole-triangle distance filter (triangles_filter_culls: where
/// it culls, it culls all 15 feature pairs of the two faces; a pair of layers resting on each
/// other is mostly this), which `run` applies to a batch at a time, vectorised (face_batch.hpp:
/// the scalar verdicts and bounds bit for bit); one per thread. `slot[k]`: where the caller's
/// k-th pair of a piece went (-1: not queued).
struct FacesApartBatch {
  static constexpr int kCapacity = ccd_detail::FacePairBatch::kCapacity;
  ccd_detail::FacePairBatch pairs;
  std::array<bool, kCapacity> apart{};
  std::array<double, kCapacity> bound_t1{};
  std::array<int, kCapacity> slot{};

  /// Queues triangle a (positions a0 at t0, a1 at t1) against triangle b; returns its slot.
  int push(std::span<const Eigen::Vector3d> a0, std::span<const Eigen::Vector3d> a1, const Face& a,
           std::span<const Eigen::Vector3d> b0, std::span<const Eigen::Vector3d> b1,
           const Face& b) {
    using ccd_detail::corners;
    pairs.push(corners(a0, a), corners(a1, a), corners(b0, b), corners(b1, b));
    return pairs.size - 1;
  }
  /// Filters the queued pairs at `thickness` into apart and bound_t1, and empties the queue.
  void run(double thickness) {
    ccd_detail::triangles_filter_batch(pairs, thickness, apart.data(), bound_t1.data());
    pairs.size = 0;
  }
};

/// Triangle pairs at one time waiting for their whole-triangle distance bound
/// (triangle_triangle_bound), which `run` computes for a batch at a time, vectorised
/// (face_batch.hpp, bit for bit); one per thread. `slot` as in FacesApartBatch.
struct FaceBoundBatch {
  static constexpr int kCapacity = ccd_detail::StaticFacePairBatch::kCapacity;
  ccd_detail::StaticFacePairBatch pairs;
  std::array<double, kCapacity> bound{};
  std::array<int, kCapacity> slot{};

  /// Queues face a (positions x) against face b (positions y); returns its slot.
  int push(std::span<const Eigen::Vector3d> x, const Face& a, std::span<const Eigen::Vector3d> y,
           const Face& b) {
    pairs.push(ccd_detail::corners(x, a), ccd_detail::corners(y, b));
    return pairs.size - 1;
  }
  /// Bounds the queued pairs into `bound`, and empties the queue.
  void run() {
    ccd_detail::triangle_bound_batch(pairs, bound.data());
    pairs.size = 0;
  }
};

/// One face's feature boxes for a step, side by side as float lanes: coordinate c of the boxes'
/// lower corners in lo[c], of their upper corners in hi[c]. Lanes 0..2 hold the boxes of the
/// face's edges (Topology::face_edges order), lane 3 the face's box, lanes 4..6 the boxes of its
/// corners (Topology::faces order), lane 7 the face's box again. A triangle pair then reads two
/// blocks of three cache lines instead of fourteen scattered boxes, and tests them four lanes at
/// a time (feature_overlaps).
struct alignas(64) FaceBoxes {
  static constexpr int kEdges = 0, kFace = 3, kCorners = 4;
  float lo[3][8], hi[3][8];

  void set(int lane, const Box& b) {
    for (int c = 0; c < 3; ++c) {
      lo[c][lane] = b.lo[c];
      hi[c][lane] = b.hi[c];
    }
  }
  [[nodiscard]] Box get(int lane) const {
    Box b;
    for (int c = 0; c < 3; ++c) {
      b.lo[c] = lo[c][lane];
      b.hi[c] = hi[c][lane];
    }
    return b;
  }
  [[nodiscard]] Box face() const { return get(kFace); }
  /// overlap(face(), o.face()), read in place: the same ordered comparisons (false on NaN),
  /// without building the two boxes (whose scalar stores a vector load would wait on).
  [[nodiscard]] bool face_overlaps(const FaceBoxes& o) const {
    bool all = true;
    for (int c = 0; c < 3; ++c)
      all = all && lo[c][kFace] <= o.hi[c][kFace] && o.lo[c][kFace] <= hi[c][kFace];
    return all;
  }
};

}  // namespace clothcd::detail
