#pragma once
// The earliest-impact query of both detectors, as detections over time windows. A window [0, T]
// is the sub-step x0 -> x(T) = x0 + T (x1 - x0), run through the detector's own pipeline (boxes,
// traversal, filters; FilterPlan::kernel) at the thickness plus an allowance for the
// rounding of x(T): its boxes and filters see only the motion up to T, so a short window holds
// few candidate pairs and filters away almost all of them. Its hits, the pairs the filters keep,
// may touch by T; the step's own kernels time them (over the whole step, as detect() would), and
// a time by T is a contact of the window. Only a window without one leads to the next, [0, 1] (the
// step itself). The earliest times are then refined to the query's tolerance (EarliestSearch).
//
// Why a window answers for the step: every pair that comes within h before T comes, in the
// computed sub-step, within h plus the allowance (each interpolated position lies within
// `rounding_slack` / 2 of the exact one), so the window reports it, and the step's kernels give
// it a time no later than its contact. Every time is a function of its pair alone, so the
// minimum, with ties broken by (kind, ids), does not depend on the thread count.

#include <Eigen/Core>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <span>
#include <tuple>
#include <type_traits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ccd/batch.hpp"
#include "clothcd/ccd/queries.hpp"
#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/topology.hpp"

namespace clothcd::detail {

/// Refuses settings the query cannot honour (InputError).
void check_earliest_options(const EarliestOptions& o);

/// The first window: options.first_window, or (0) the largest power of two T <= 1 with
/// T * (largest displacement) <= (mean edge length) / 64 over the meshes given, at least 2^-30.
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
  }

  /// The hits of window [0, t] (a window's detection with the settings of `window_options`:
  /// their times are its own); with t = 1 the step's, already timed by the step's kernels.
  void add(std::span<const VertexFaceCollision> vf, std::span<const EdgeEdgeCollision> ee, double t,
           bool vertex_on_b) {
    using Kind = EarliestImpact::Kind;
    const std::size_t first = hits_.size();
    for (const VertexFaceCollision& c : vf)
      hits_.push_back({c.toi, Kind::VertexFace, vertex_on_b, {c.vertex, c.face}});
    for (const EdgeEdgeCollision& c : ee)
      hits_.push_back({c.toi, Kind::EdgeEdge, false, {c.edge_a, c.edge_b}});
    if (t == 1.0) return;
    // A window's hit is a pair that may touch by t; the step's kernels time it, and only a time
    // by t counts (every pair touching by t has one: the kernels are never late).
    tbb::parallel_for(tbb::blocked_range<std::size_t>(first, hits_.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          Hit& h = hits_[i];
                          const CcdResult k = h.kind == Kind::VertexFace
                                                  ? vertex_face_ccd(query_vf(h), kernel_)
                                                  : edge_edge_ccd(query_ee(h), kernel_);
                          h.toi = k.hit && k.toi <= t ? k.toi : 2.0;
                        }
                      });
    std::erase_if(hits_, [](const Hit& h) { return h.toi > 1.0; });
  }

  /// The earliest hit, its time refined to the query's tolerance (None when there is no hit);
  /// forgets the hits. A refined time is never earlier than the coarse one, so the hits are
  /// refined in the order of their coarse times until one comes after the best so far.
  [[nodiscard]] EarliestImpact take_earliest() {
    std::sort(hits_.begin(), hits_.end(), [](const Hit& x, const Hit& y) {
      return std::tuple(x.toi, x.kind, x.vertex_on_b, x.ids) <
             std::tuple(y.toi, y.kind, y.vertex_on_b, y.ids);
    });
    CcdOptions fine = kernel_;
    fine.toi_tolerance = tolerance_;
    EarliestImpact best;
    for (const Hit& h : hits_) {
      EarliestImpact e;
      e.toi = h.toi;
      e.kind = h.kind;
      e.ids = h.ids;
      e.vertex_on_b = h.vertex_on_b;
      if (!(earliest_key(e) < earliest_key(best))) break;
      if (tolerance_ < kernel_.toi_tolerance) e.toi = refine(h, fine, best.toi);
      if (earliest_key(e) < earliest_key(best)) best = e;
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
  };
  // A hit's time at the fine tolerance, or `cap` (the best time so far) where it cannot come
  // before it: one existence query over [coarse time, cap] settles most of the hits that lose
  // (a thickness makes many pairs meet at nearly one time). Then at zero thickness the kernel's
  // own fine search, where it is no earlier than the coarse time and within its box budget (the
  // fast path certifies it from the coplanarity cubic, tighter than any box search); otherwise,
  // and where a thickness makes that search run out of boxes, the bisection.
  [[nodiscard]] double refine(const Hit& h, const CcdOptions& fine, double cap) const {
    const auto one = [&](const auto& q) {
      if (!ccd_detail::may_touch(q, fine, h.toi, cap)) return cap;
      if (fine.thickness == 0) {
        CcdResult k;
        if constexpr (std::is_same_v<std::decay_t<decltype(q)>, VertexFaceQuery>) {
          k = vertex_face_ccd(q, fine);
        } else {
          k = edge_edge_ccd(q, fine);
        }
        if (settled(k, h, fine)) return std::min(k.toi, cap);
      }
      return std::min(cap, ccd_detail::refine_time_of_impact(q, fine, h.toi, cap));
    };
    return h.kind == EarliestImpact::Kind::VertexFace ? one(query_vf(h)) : one(query_ee(h));
  }
  // Whether the kernel's fine time stands: a hit, no earlier than the coarse time, within its
  // box budget (an exhausted search reports its earliest open time instead).
  [[nodiscard]] static bool settled(const CcdResult& k, const Hit& h, const CcdOptions& fine) {
    return k.hit && k.toi >= h.toi && k.boxes < fine.max_boxes;
  }
  [[nodiscard]] VertexFaceQuery query_vf(const Hit& h) const {
    return make_vf_(h.ids[0], h.ids[1], h.vertex_on_b);
  }
  [[nodiscard]] EdgeEdgeQuery query_ee(const Hit& h) const { return make_ee_(h.ids[0], h.ids[1]); }

  CcdOptions kernel_;
  double tolerance_;
  MakeVf make_vf_;
  MakeEe make_ee_;
  std::vector<Hit> hits_;
};

/// The windows' search, shared by the detectors: `detect_window(t, slack, stats)` detects the
/// window [0, t] (with t = 1 the step itself, slack 0) and adds its hits to `search`. A window
/// answers when its earliest refined time is within it: every pair touching by t is among its
/// hits, and no other can come before them.
template <class Search, class DetectWindow>
EarliestImpact search_windows(double first, double slack, Search& search,
                              DetectWindow&& detect_window) {
  DetectStats stats;
  int windows = 0;
  EarliestImpact best;
  for (double t = first;; t = 1.0) {
    ++windows;
    detect_window(t, t < 1 ? slack : 0.0, stats);
    best = search.take_earliest();
    if ((best.kind != EarliestImpact::Kind::None && best.toi <= t) || t == 1.0) break;
  }
  best.windows = windows;
  best.first_window = first;
  best.stats = stats;
  return best;
}

}  // namespace clothcd::detail
