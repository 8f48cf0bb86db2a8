#pragma once
// The earliest-impact query of both detectors, as detections over time windows. A window
// [lo, hi] is the sub-step x(lo) -> x(hi), x(t) = x0 + t (x1 - x0), run through the detector's
// own pipeline (boxes, traversal, filters; FilterPlan::kernel) at the thickness plus an
// allowance for the rounding of x(t): its boxes and filters see only the motion over
// [lo, hi], so a short window holds few candidate pairs and filters away almost all of them. Its
// hits, the pairs the filters keep, may touch in it; the step's own kernels time them (over the
// whole step, as detect() would), and a time by hi is a contact of the window. Only a window
// without one leads to the next, longer one (search_windows). The earliest times are then refined
// to the query's tolerance (EarliestSearch).
//
// Why a window answers for the step: every pair that comes within h in [lo, hi] comes, in the
// computed sub-step, within h plus the allowance (each interpolated position lies within
// `rounding_slack` / 2 of the exact one), so the window reports it, and the step's kernels give
// it a time no later than its contact; the earlier windows held no contact. The hits are timed
// in an order and in batches fixed by the hits alone, and ties go to the smallest (kind, ids),
// so the answer does not depend on the thread count.

#include <Eigen/Core>

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <limits>
#include <span>
#include <tuple>
#include <type_traits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ccd/batch.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/ccd/queries.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/topology.hpp"

namespace clothcd::detail {

/// Refuses settings the query cannot honour (InputError).
void check_earliest_options(const EarliestOptions& o);

/// The automatic first window's reach: no vertex moves more than this share of the mean edge
/// length in it. A window costs at least what the boxes overlapping at rest cost, and little
/// more as it grows to a few edge lengths' motion: a quarter of an edge holds the first contact
/// of most steps measured (docs/results/earliest.md) at a few percent over the shortest windows.
inline constexpr double kFirstWindowShare = 4;

/// The first window: options.first_window, or (0) the largest power of two T <= 1 with
/// T * (largest displacement) <= (mean edge length) / kFirstWindowShare over the meshes given,
/// at least 2^-30.
[[nodiscard]] double first_window(const EarliestOptions& options,
                                  std::span<const Topology* const> meshes,
                                  std::span<const std::span<const Eigen::Vector3d>> x0,
                                  std::span<const std::span<const Eigen::Vector3d>> x1);

/// Contact distance to add in a window: twice the largest distance between a computed x(T) and
/// the exact one (at most 5 u max|x| per coordinate, u the unit roundoff), in the Euclidean norm
/// and rounded up generously.
[[nodiscard]] inline double rounding_slack(std::span<const Eigen::Vector3d> x0,
                                           std::span<const Eigen::Vector3d> x1) {
  double m = 0;
  for (std::size_t i = 0; i < x0.size(); ++i)
    m = std::max({m, x0[i].cwiseAbs().maxCoeff(), x1[i].cwiseAbs().maxCoeff()});
  return 64 * (DBL_EPSILON / 2) * m + 64 * std::numeric_limits<double>::denorm_min();
}

/// x0 + t (x1 - x0) for every vertex (t a power of two, so t (x1 - x0) is exact).
inline void interpolate(std::span<const Eigen::Vector3d> x0, std::span<const Eigen::Vector3d> x1,
                        double t, std::vector<Eigen::Vector3d>& out) {
  out.resize(x0.size());
  for (std::size_t i = 0; i < x0.size(); ++i)
    out[i] = x0[i] + t * (x1[i] - x0[i]);
}

/// The order of EarliestImpact::ids ties: time, then kind, side and ids.
[[nodiscard]] inline auto earliest_key(const EarliestImpact& e) {
  return std::tuple(e.toi, e.kind == EarliestImpact::Kind::None, e.kind, e.vertex_on_b, e.ids);
}

/// The detector's options `o` for a window's detection: the contact distance plus the window's
/// rounding allowance, the step kernels' coarse time tolerance, and nothing kept for later calls
/// (pairs for reuse, the traversal's front).
[[nodiscard]] inline DetectOptions window_options(DetectOptions o, double slack,
                                                  double toi_tolerance) {
  o.thickness += slack;
  o.toi_tolerance = toi_tolerance;
  o.reuse_distance = 0;
  o.reuse_front = false;
  return o;
}

/// Adds a window's counters and times into the query's.
void add_stats(const DetectStats& window, DetectStats& total);

/// The time tolerance of the step's kernels on the windows' hits and of the step's own detection:
/// each pair is timed to this first, and only the pairs that can still come first are refined to
/// the query's tolerance (refine_time_of_impact).
inline constexpr double kCoarseToiTolerance = 1e-4;

/// The hits of the windows, timed by the step's own kernels, and the earliest of them refined.
/// `make_vf(vertex, face, vertex_on_b)` and `make_ee(edge_a, edge_b)` give a pair's query over
/// the step; `step_kernel` (the detector's thickness and kernel settings) times it.
template <class MakeVf, class MakeEe>
class EarliestSearch {
 public:
  EarliestSearch(const CcdOptions& step_kernel, double toi_tolerance, MakeVf make_vf,
                 MakeEe make_ee)
      : kernel_(step_kernel), tolerance_(toi_tolerance), make_vf_(make_vf), make_ee_(make_ee) {
    kernel_.toi_tolerance = std::max(toi_tolerance, kCoarseToiTolerance);
    fine_ = kernel_;
    fine_.toi_tolerance = tolerance_;
  }

  /// Adds the hits of a window's detection (with the settings of `window_options`; for the
  /// whole step in one window, a detection with kernels, whose times are the kernels' own).
  void add(std::span<const VertexFaceCollision> vf, std::span<const EdgeEdgeCollision> ee,
           bool vertex_on_b) {
    using Kind = EarliestImpact::Kind;
    for (const VertexFaceCollision& c : vf)
      hits_.push_back({c.toi, Kind::VertexFace, vertex_on_b, {c.vertex, c.face}});
    for (const EdgeEdgeCollision& c : ee)
      hits_.push_back({c.toi, Kind::EdgeEdge, false, {c.edge_a, c.edge_b}});
  }

  /// The earliest of the hits added, its time refined to the query's tolerance, among the times
  /// by `hi` (None when there is none); forgets the hits. `timed`: the hits carry the kernels'
  /// times (the whole step in one window); otherwise they are a window's candidates, and the
  /// step's kernels time them here (over the whole step: every pair touching by hi gets a time
  /// by hi, the kernels are never late).
  ///
  /// Untimed hits go in order of a lower bound on when they can touch, in batches of growing
  /// size; the kernels of a batch run in parallel, each pair first asking whether it can touch
  /// before the best refined time of the earlier batches (one existence query), so that once a
  /// small time is known the other pairs cost little. A pair that cannot touch by then never
  /// comes first. The batches depend on the hits alone, so the answer does not depend on the
  /// thread count.
  [[nodiscard]] EarliestImpact take_earliest(double hi, bool timed) {
    EarliestImpact best;
    if (timed) {
      best = refine_earliest(hits_.begin(), hits_.end(), best);
      hits_.clear();
      return best;
    }
    order_by_reach();
    std::size_t size = kFirstBatch;
    for (std::size_t first = 0; first < hits_.size();
         first += size, size = std::min(2 * size, kLastBatch)) {
      const std::size_t last = std::min(hits_.size(), first + size);
      const double cap = std::min(hi, best.toi);
      const bool known = best.kind != EarliestImpact::Kind::None;
      tbb::parallel_for(tbb::blocked_range<std::size_t>(first, last, 8),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i)
                            hits_[i].toi = coarse_time(hits_[i], cap, known ? &best : nullptr);
                        });
      const auto batch_end = std::partition(hits_.begin() + static_cast<std::ptrdiff_t>(first),
                                            hits_.begin() + static_cast<std::ptrdiff_t>(last),
                                            [](const Hit& h) { return h.toi <= 1.0; });
      best = refine_earliest(hits_.begin() + static_cast<std::ptrdiff_t>(first), batch_end, best);
    }
    hits_.clear();
    return best;
  }

  /// The step kernels' settings at the coarse tolerance.
  [[nodiscard]] const CcdOptions& kernel() const { return kernel_; }

 private:
  struct Hit {
    double toi;
    EarliestImpact::Kind kind;
    bool vertex_on_b;
    std::array<int, 2> ids;
    // For a window's hits: a lower bound on the features' distance at t0, and the largest
    // relative displacement of their points over the step (reach()).
    double gap = 0, speed = 0;
    double distance = 0;  // the features' distance at t0 (as computed)
  };
  // The first batch is small, so that a first time is known early; later ones are larger, so
  // that their parallel loops stay worth starting.
  static constexpr std::size_t kFirstBatch = 16;
  static constexpr std::size_t kLastBatch = 1024;

  // Orders the hits by when they could first touch: the distance at t0 beyond the thickness
  // over the largest relative displacement of their points (an order only: the times come from
  // the kernels), ties by (kind, side, ids). Keeps each hit's bounds for can_touch().
  void order_by_reach() {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, hits_.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                          reach(hits_[i]);
                      });
    std::sort(hits_.begin(), hits_.end(),
              [](const Hit& x, const Hit& y) { return key(x) < key(y); });
  }
  // Over the step the distance of two features falls by at most t times the largest relative
  // displacement of their points (the closest points are convex combinations of them).
  void reach(Hit& h) const {
    double d = 0;
    h.speed = 0;
    if (h.kind == EarliestImpact::Kind::VertexFace) {
      const VertexFaceQuery q = query_vf(h);
      d = point_triangle_proximity(q.v_t0, q.f0_t0, q.f1_t0, q.f2_t0).distance;
      h.gap = point_triangle_distance_lower_bound(q.v_t0, q.f0_t0, q.f1_t0, q.f2_t0);
      const Eigen::Vector3d dv = q.v_t1 - q.v_t0;
      for (const auto& [a, b] :
           {std::pair{&q.f0_t0, &q.f0_t1}, {&q.f1_t0, &q.f1_t1}, {&q.f2_t0, &q.f2_t1}})
        h.speed = std::max(h.speed, (dv - (*b - *a)).norm());
    } else {
      const EdgeEdgeQuery q = query_ee(h);
      d = edge_edge_proximity(q.ea0_t0, q.ea1_t0, q.eb0_t0, q.eb1_t0).distance;
      h.gap = edge_edge_distance_lower_bound(q.ea0_t0, q.ea1_t0, q.eb0_t0, q.eb1_t0);
      for (const auto& [a, b] : {std::pair{&q.ea0_t0, &q.ea0_t1}, {&q.ea1_t0, &q.ea1_t1}})
        for (const auto& [c, e] : {std::pair{&q.eb0_t0, &q.eb0_t1}, {&q.eb1_t0, &q.eb1_t1}})
          h.speed = std::max(h.speed, ((*b - *a) - (*e - *c)).norm());
    }
    h.distance = d;
    const double gap = std::max(0.0, d - kernel_.thickness);
    h.toi = gap == 0 ? 0.0 : h.speed > 0 ? gap / h.speed : INFINITY;
  }
  // Whether the hit's features can come within the thickness by `cap` by reach()'s bound, with
  // a relative allowance for the rounding of the bounds (the distance's lower bound allows for
  // its own).
  [[nodiscard]] bool can_touch(const Hit& h, double cap) const {
    return h.gap <= (kernel_.thickness + cap * h.speed * (1 + 1e-9)) * (1 + 1e-12);
  }
  [[nodiscard]] static auto key(const Hit& h) {
    return std::tuple(h.toi, h.kind, h.vertex_on_b, h.ids);
  }

  // A window's hit timed by the step's kernel at the coarse tolerance: its time if by `cap`,
  // otherwise 2. Where the best refined time so far is known (`best`, at most cap), a pair that
  // cannot come before it is dropped: at time 0 every pair of a larger (kind, ids) (no time is
  // earlier, and ties go to the smaller), otherwise each that cannot touch by cap, by its
  // distance and speed (can_touch) or else by one existence query.
  [[nodiscard]] double coarse_time(const Hit& h, double cap, const EarliestImpact* best) const {
    if (best != nullptr && best->toi == 0 &&
        std::tuple(h.kind, h.vertex_on_b, h.ids) >
            std::tuple(best->kind, best->vertex_on_b, best->ids)) {
      return 2.0;
    }
    if (best != nullptr && !can_touch(h, cap)) return 2.0;
    const auto one = [&](const auto& q) {
      if (best != nullptr) {
        // The separating direction first (a few dot products; may_touch's search tries it too,
        // but only after its first 1,024 boxes: on dress-rumba 60 -> 61 unsewn the query takes
        // 114 M instructions with this call, 191 M without), then the search: over may_touch's
        // interval (cap rounded up to the kernel's time grid) and beyond the distance a kernel
        // hit certifies, so that a pair it drops is one without a hit by cap.
        const double reach = ccd_detail::certified_distance(q, kernel_);
        if (ccd_detail::stay_apart(q, std::min(1.0, cap + 2 * kernel_.toi_tolerance), reach)) {
          return 2.0;
        }
        // A pair already within that distance at t0 keeps the search looking for long before it
        // finds the box it cannot reject (on a stitched seam, thousands of them): the kernel
        // times it at once.
        if (!(h.distance <= reach) && !ccd_detail::may_touch(q, kernel_, 0.0, cap)) return 2.0;
      }
      CcdResult k;
      if constexpr (std::is_same_v<std::decay_t<decltype(q)>, VertexFaceQuery>) {
        k = vertex_face_ccd(q, kernel_);
      } else {
        k = edge_edge_ccd(q, kernel_);
      }
      return k.hit && k.toi <= cap ? k.toi : 2.0;
    };
    return h.kind == EarliestImpact::Kind::VertexFace ? one(query_vf(h)) : one(query_ee(h));
  }

  // The earliest of [first, last) (coarse times) refined, against `best`. A refined time is
  // never earlier than the coarse one, so the hits are refined in the order of their coarse
  // times until one comes after the best so far.
  template <class It>
  [[nodiscard]] EarliestImpact refine_earliest(It first, It last, EarliestImpact best) const {
    std::sort(first, last, [](const Hit& x, const Hit& y) { return key(x) < key(y); });
    for (It it = first; it != last; ++it) {
      const Hit& h = *it;
      EarliestImpact e;
      e.toi = h.toi;
      e.kind = h.kind;
      e.ids = h.ids;
      e.vertex_on_b = h.vertex_on_b;
      if (!(earliest_key(e) < earliest_key(best))) break;
      if (tolerance_ < kernel_.toi_tolerance) e.toi = refine(h, best.toi);
      if (earliest_key(e) < earliest_key(best)) best = e;
    }
    return best;
  }
  // A hit's time at the fine tolerance, or `cap` (the best time so far) where it cannot come
  // before it: one existence query over [coarse time, cap] settles most of the hits that lose
  // (a thickness makes many pairs meet at nearly one time). Then at zero thickness the kernel's
  // own fine search, where it is no earlier than the coarse time and within its box budget (the
  // fast path certifies it from the coplanarity cubic, tighter than any box search); otherwise,
  // and where a thickness makes that search run out of boxes, the bisection.
  [[nodiscard]] double refine(const Hit& h, double cap) const {
    const auto one = [&](const auto& q) {
      if (!ccd_detail::may_touch(q, fine_, h.toi, cap)) return cap;
      if (fine_.thickness == 0) {
        CcdResult k;
        if constexpr (std::is_same_v<std::decay_t<decltype(q)>, VertexFaceQuery>) {
          k = vertex_face_ccd(q, fine_);
        } else {
          k = edge_edge_ccd(q, fine_);
        }
        if (settled(k, h)) return std::min(k.toi, cap);
      }
      return std::min(cap, ccd_detail::refine_time_of_impact(q, fine_, h.toi, cap));
    };
    return h.kind == EarliestImpact::Kind::VertexFace ? one(query_vf(h)) : one(query_ee(h));
  }
  // Whether the kernel's fine time stands: a hit, no earlier than the coarse time, within its
  // box budget (an exhausted search reports its earliest open time instead).
  [[nodiscard]] bool settled(const CcdResult& k, const Hit& h) const {
    return k.hit && k.toi >= h.toi && k.boxes < fine_.max_boxes;
  }
  [[nodiscard]] VertexFaceQuery query_vf(const Hit& h) const {
    return make_vf_(h.ids[0], h.ids[1], h.vertex_on_b);
  }
  [[nodiscard]] EdgeEdgeQuery query_ee(const Hit& h) const { return make_ee_(h.ids[0], h.ids[1]); }

  CcdOptions kernel_, fine_;
  double tolerance_;
  MakeVf make_vf_;
  MakeEe make_ee_;
  std::vector<Hit> hits_;
};

/// How much longer each window is than the one before.
inline constexpr double kWindowGrowth = 4;

/// The windows' search, shared by the detectors: `detect_window(lo, hi, slack, stats)` detects
/// the window [lo, hi] (the sub-step x(lo) -> x(hi); [0, 1] is the step itself, with slack 0)
/// and adds its hits to `search`. The windows are [0, first], then each kWindowGrowth times as
/// long as the one before, up to 1. A window answers when its earliest refined time is by its
/// end: every pair touching by then touches in it (the earlier windows had none), so it is
/// among its hits, and no other can come before them.
template <class Search, class DetectWindow>
EarliestImpact search_windows(double first, double slack, Search& search,
                              DetectWindow&& detect_window) {
  DetectStats stats;
  int windows = 0;
  EarliestImpact best;
  for (double lo = 0, hi = first;; lo = hi, hi = std::min(1.0, hi * kWindowGrowth)) {
    ++windows;
    // The kernels timing the window's hits and the refinement count as narrow phase, with the
    // interpolation of the window's positions: the stats give the whole query's time.
    const auto start = std::chrono::steady_clock::now();
    const double stages = stats.time_refit + stats.time_traverse + stats.time_narrow;
    const bool whole = lo == 0 && hi == 1;
    detect_window(lo, hi, whole ? 0.0 : slack, stats);
    best = search.take_earliest(hi, whole);
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats.time_narrow +=
        std::max(0.0, took - (stats.time_refit + stats.time_traverse + stats.time_narrow - stages));
    if ((best.kind != EarliestImpact::Kind::None && best.toi <= hi) || hi == 1.0) break;
  }
  best.windows = windows;
  best.first_window = first;
  best.stats = stats;
  return best;
}

}  // namespace clothcd::detail
