#pragma once
// Feature-level tests shared by the detector and the brute-force oracle, so both put every VF and
// EE pair through exactly the same box test, NP filter and kernel.

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

#include "ccd/face_batch.hpp"
#include "ccd/face_bounds.hpp"
#include "ccd/np_batch.hpp"
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
  static constexpr int kCapacity = FacePairBatch::kCapacity;
  FacePairBatch pairs;
  std::array<bool, kCapacity> apart{};
  std::array<double, kCapacity> bound_t1{};
  std::array<int, kCapacity> slot{};

  /// Queues triangle a (positions a0 at t0, a1 at t1) against triangle b; returns its slot.
  int push(std::span<const Eigen::Vector3d> a0, std::span<const Eigen::Vector3d> a1, const Face& a,
           std::span<const Eigen::Vector3d> b0, std::span<const Eigen::Vector3d> b1,
           const Face& b) {
    pairs.push(corners(a0, a), corners(a1, a), corners(b0, b), corners(b1, b));
    return pairs.size - 1;
  }
  /// Filters the queued pairs at `thickness` into apart and bound_t1, and empties the queue.
  void run(double thickness) {
    triangles_filter_batch(pairs, thickness, apart.data(), bound_t1.data());
    pairs.size = 0;
  }
};

/// Triangle pairs at one time waiting for their whole-triangle distance bound
/// (triangle_triangle_bound), which `run` computes for a batch at a time, vectorised
/// (face_batch.hpp, bit for bit); one per thread. `slot` as in FacesApartBatch.
struct FaceBoundBatch {
  static constexpr int kCapacity = StaticFacePairBatch::kCapacity;
  StaticFacePairBatch pairs;
  std::array<double, kCapacity> bound{};
  std::array<int, kCapacity> slot{};

  /// Queues face a (positions x) against face b (positions y); returns its slot.
  int push(std::span<const Eigen::Vector3d> x, const Face& a, std::span<const Eigen::Vector3d> y,
           const Face& b) {
    pairs.push(corners(x, a), corners(y, b));
    return pairs.size - 1;
  }
  /// Bounds the queued pairs into `bound`, and empties the queue.
  void run() {
    triangle_bound_batch(pairs, bound.data());
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

/// Positions of one step and the test settings.
struct FeatureContext {
  const Topology* topo = nullptr;
  std::span<const Eigen::Vector3d> v0, v1;
  double margin = 0;  // thickness / 2
  bool np_filter = true;
  bool zero_thickness_distance = false;  // DetectOptions::distance_filter
  int distance_depth = 0;                // DetectOptions::distance_filter_depth
  CcdOptions ccd;
  /// Optional swept boxes of every vertex, edge and face for this step (`precompute_boxes`);
  /// empty: computed on demand.
  std::span<const Box> vboxes, eboxes, fboxes;
  /// Optional: the same boxes gathered per face (FeatureBoxes built with face blocks); empty
  /// otherwise.
  std::span<const FaceBoxes> face_boxes;
  /// DetectOptions::linked_vertices as (smaller, larger), sorted and unique (`sorted_links`).
  std::span<const std::pair<int, int>> links;

  [[nodiscard]] bool grouped(int u, int v) const {
    if (links.empty()) return false;
    const std::pair<int, int> k = u < v ? std::pair(u, v) : std::pair(v, u);
    return std::binary_search(links.begin(), links.end(), k);
  }

  [[nodiscard]] Box compute_face_box(int f) const {
    const Face& t = topo->faces()[f];
    return swept_feature_box({&v0[t[0]], &v0[t[1]], &v0[t[2]], &v1[t[0]], &v1[t[1]], &v1[t[2]]},
                             margin);
  }
  [[nodiscard]] Box compute_vertex_box(int v) const {
    return swept_feature_box({&v0[v], &v1[v]}, margin);
  }
  [[nodiscard]] Box compute_edge_box(int e) const {
    const Edge& d = topo->edges()[e];
    return swept_feature_box({&v0[d[0]], &v0[d[1]], &v1[d[0]], &v1[d[1]]}, margin);
  }
  [[nodiscard]] Box face_box(int f) const {
    return fboxes.empty() ? compute_face_box(f) : fboxes[f];
  }
  [[nodiscard]] Box vertex_box(int v) const {
    return vboxes.empty() ? compute_vertex_box(v) : vboxes[v];
  }
  [[nodiscard]] Box edge_box(int e) const {
    return eboxes.empty() ? compute_edge_box(e) : eboxes[e];
  }

  /// Whether a vertex of the pair is linked to one of the other: such pairs are never tested.
  [[nodiscard]] bool vf_linked(int v, int f) const {
    const Face& t = topo->faces()[f];
    return grouped(v, t[0]) || grouped(v, t[1]) || grouped(v, t[2]);
  }
  [[nodiscard]] bool ee_linked(int ea, int eb) const {
    const Edge& a = topo->edges()[ea];
    const Edge& b = topo->edges()[eb];
    return grouped(a[0], b[0]) || grouped(a[0], b[1]) || grouped(a[1], b[0]) || grouped(a[1], b[1]);
  }

  /// Vertex v against face f (their boxes already overlap): NP filter, then the kernel.
  void kernel_vf(int v, int f, FeatureCounters& c, std::vector<VertexFaceCollision>& out) const {
    if (vf_linked(v, f)) return;
    const Face& t = topo->faces()[f];
    const VertexFaceQuery q{v0[v], v0[t[0]], v0[t[1]], v0[t[2]],
                            v1[v], v1[t[0]], v1[t[1]], v1[t[2]]};
    double toi = 1.0;
    if (ccd_hit(q, c.vf_tests, c.vf_np, toi)) out.push_back({v, f, t, toi});
  }

  /// Edges ea < eb (their boxes already overlap).
  void kernel_ee(int ea, int eb, FeatureCounters& c, std::vector<EdgeEdgeCollision>& out) const {
    if (ee_linked(ea, eb)) return;
    const Edge& a = topo->edges()[ea];
    const Edge& b = topo->edges()[eb];
    const EdgeEdgeQuery q{v0[a[0]], v0[a[1]], v0[b[0]], v0[b[1]],
                          v1[a[0]], v1[a[1]], v1[b[0]], v1[b[1]]};
    double toi = 1.0;
    if (ccd_hit(q, c.ee_tests, c.ee_np, toi)) out.push_back({ea, eb, a, b, toi});
  }

  /// kernel_vf deferred to a batch: the pairs the batched filters cull are counted as kernel_vf
  /// counts them, the others go through kernel_vf's path (all of them without a vectorised
  /// filter in the settings, batched()). `flush` tests what is left.
  void queue_vf(int v, int f, FeatureBatch& b, FeatureCounters& c,
                std::vector<VertexFaceCollision>& out) const {
    queue_vf(v, f, topo->faces()[f], b, c, out);
  }
  /// The same, given f's corners `t` (topo->faces()[f]).
  void queue_vf(int v, int f, const Face& t, FeatureBatch& b, FeatureCounters& c,
                std::vector<VertexFaceCollision>& out) const {
    if (!links.empty() && vf_linked(v, f)) return;
    if (b.push_vf({v, f}, vf_points(v, *this, t))) flush_vf(b, c, out);
  }
  /// kernel_ee deferred to a batch (as queue_vf).
  void queue_ee(int ea, int eb, FeatureBatch& b, FeatureCounters& c,
                std::vector<EdgeEdgeCollision>& out) const {
    queue_ee(ea, eb, topo->edges()[ea], topo->edges()[eb], b, c, out);
  }
  /// The same, given the edges' vertices `a` and `d` (topo->edges()[ea], [eb]).
  void queue_ee(int ea, int eb, const Edge& a, const Edge& d, FeatureBatch& b, FeatureCounters& c,
                std::vector<EdgeEdgeCollision>& out) const {
    if (!links.empty() && ee_linked(ea, eb)) return;
    if (b.push_ee({ea, eb}, ee_points(a, *this, d))) flush_ee(b, c, out);
  }
  /// The points of vertex v of this context's mesh against face t of side `sf`'s (this one, or
  /// the other mesh's in a two-mesh detection), in the batches' order.
  [[nodiscard]] std::array<const double*, 8> vf_points(int v, const FeatureContext& sf,
                                                       const Face& t) const {
    return {v0[v].data(), sf.v0[t[0]].data(), sf.v0[t[1]].data(), sf.v0[t[2]].data(),
            v1[v].data(), sf.v1[t[0]].data(), sf.v1[t[1]].data(), sf.v1[t[2]].data()};
  }
  /// The points of edge a of this context's mesh against edge d of side `sd`'s.
  [[nodiscard]] std::array<const double*, 8> ee_points(const Edge& a, const FeatureContext& sd,
                                                       const Edge& d) const {
    return {v0[a[0]].data(), v0[a[1]].data(), sd.v0[d[0]].data(), sd.v0[d[1]].data(),
            v1[a[0]].data(), v1[a[1]].data(), sd.v1[d[0]].data(), sd.v1[d[1]].data()};
  }
  /// Tests the pairs still queued in `b`.
  void flush(FeatureBatch& b, FeatureCounters& c, std::vector<VertexFaceCollision>& vf,
             std::vector<EdgeEdgeCollision>& ee) const {
    flush_vf(b, c, vf);
    flush_ee(b, c, ee);
  }

  /// Tests the queries queued in `q` (b.vf or b.ee, of kind `kind`; b's other arrays serve as
  /// scratch) as ccd_hit tests them, and empties it: the batch filters, then the kernel on what
  /// they keep (without a vectorised filter in the settings, batched(), ccd_hit's own path one
  /// query at a time). Counts each query in `tests` and a filter's cull in `culled`; calls
  /// hit(i, toi) for each query i that collides. The same verdicts, counts and times of impact
  /// as ccd_hit one query at a time.
  template <class Hit>
  void flush_queries(ccd_detail::Kind kind, ccd_detail::NpBatch& q, FeatureBatch& b,
                     std::uint64_t& tests, std::uint64_t& culled, Hit&& hit) const {
    if (q.size == 0) return;
    filter_batch(kind, q, b);
    const bool settle = settles();
    for (int i = 0; i < q.size; ++i) {
      ++tests;
      if (b.verdict[i] == ccd_detail::NpVerdict::Culled) {
        culled += np_filter ? 1 : 0;
        continue;
      }
      if (settle && b.settled[i] != ccd_detail::FastSettled::Run) {  // the kernel's own answer
        if (b.settled[i] == ccd_detail::FastSettled::Hit) hit(i, b.toi[i]);
        continue;
      }
      double toi = 1.0;
      const bool kept = b.verdict[i] == ccd_detail::NpVerdict::Kept;
      const bool collides = kind == ccd_detail::Kind::VertexFace
                                ? ccd_test(query_at<VertexFaceQuery>(q, i), culled, toi, kept)
                                : ccd_test(query_at<EdgeEdgeQuery>(q, i), culled, toi, kept);
      if (collides) hit(i, toi);
    }
    q.size = 0;
  }

  /// One feature query of any mesh or meshes through this context's filters and kernel: the NP
  /// filter or the distance filter (whichever the settings use), then the kernel. Counts the
  /// test in `tests` and a filter's cull in `culled`; on a hit sets `toi`.
  template <class Query>
  bool ccd_hit(const Query& q, std::uint64_t& tests, std::uint64_t& culled, double& toi) const {
    ++tests;
    return ccd_test(q, culled, toi);
  }

  /// Whether the distance filter is the one in use (thickness > 0, filters on).
  [[nodiscard]] bool distance_at_thickness() const { return np_filter && ccd.thickness > 0; }
  /// Whether triangle pairs go through the whole-triangle distance bound first: with the distance
  /// filter, or at zero thickness with DetectOptions::distance_filter.
  [[nodiscard]] bool faces_apart_filter() const {
    return np_filter && (ccd.thickness > 0 || zero_thickness_distance);
  }

  /// Whether the distance filter runs at zero thickness too (DetectOptions::distance_filter, with
  /// np_filter) on feature pairs: on the pairs the NP filter keeps, at depth kZeroThicknessDepth.
  [[nodiscard]] bool distance_at_zero() const {
    return np_filter && zero_thickness_distance && ccd.thickness == 0;
  }
  /// Bisections of that filter: on cloth_ball 92 -> 93 it culls 44% of the pairs the NP filter
  /// keeps at depth 0, 80% at depth 2, each a search the fast path is spared; deeper costs more
  /// than its further culls save.
  static constexpr int kZeroThicknessDepth = 2;

  /// Whether a query's first test is the cubic NP filter (unscaled_np_filter), whose culls the
  /// batched filter may decide: at zero thickness, as the separate filter or as the fast path's
  /// first step.
  [[nodiscard]] bool batched_np() const {
    return ccd.thickness == 0 && (np_filter || ccd.fast_path);
  }
  /// Whether queue_vf / queue_ee defer pairs to a batch: where a query's first test has a
  /// vectorised form, the cubic NP filter at zero thickness (batched_np) or the distance filter
  /// at a thickness (distance_at_thickness). In a simulator's contact stage (a thickness, pairs
  /// mostly resting at about that distance) the distance filter culls nearly all of them.
  [[nodiscard]] bool batched() const { return batched_np() || distance_at_thickness(); }

 private:
  // ccd_hit without counting the test. `kept`: the batch's filters have kept q already (at zero
  // thickness unscaled_np_filter's verdict is Kept, then np_filter_culls is false and the kernel
  // need not run that filter again; at a thickness the distance filter has not culled it).
  template <class Query>
  bool ccd_test(const Query& q, std::uint64_t& culled, double& toi, bool kept = false) const {
    // At zero thickness the distance filter tests what the NP filter keeps, as in the batches.
    if (!kept &&
        ((separate_np() && np_filter_culls(q)) ||
         (distance_at_thickness() && distance_filter_culls(q, ccd.thickness, distance_depth)) ||
         (distance_at_zero() && !np_filter_culls(q) &&
          distance_filter_culls(q, 0.0, kZeroThicknessDepth)))) {
      ++culled;
      return false;
    }
    const CcdResult r =
        kept && ccd.thickness == 0 ? ccd_kernel_np_kept(q, ccd) : ccd_kernel(q, ccd);
    culled += counted_np(r);
    if (r.hit) toi = r.toi;
    return r.hit;
  }

  // Whether the batches settle queries with the zero-thickness kernel's own search.
  [[nodiscard]] bool settles() const { return ccd.fast_path && ccd.thickness == 0; }

  // The batch's filters in ccd_test's order. Without a vectorised filter none (every verdict
  // Undecided: ccd_test decides). At a thickness the distance filter alone (every query starts
  // Kept). At zero thickness the NP filter, the distance filter on what it keeps
  // (distance_at_zero), and with the fast path the kernel's own search down to kSettleLevel.
  void filter_batch(ccd_detail::Kind kind, const ccd_detail::NpBatch& q, FeatureBatch& b) const {
    if (!batched()) {
      std::fill_n(b.verdict.begin(), q.size, ccd_detail::NpVerdict::Undecided);
      return;
    }
    if (distance_at_thickness()) {
      std::fill_n(b.verdict.begin(), q.size, ccd_detail::NpVerdict::Kept);
      ccd_detail::distance_filter_batch(kind, q, ccd.thickness, distance_depth, b.verdict.data());
      return;
    }
    ccd_detail::np_filter_batch(kind, q, b.verdict.data());
    if (distance_at_zero()) {
      ccd_detail::distance_filter_batch(kind, q, 0.0, kZeroThicknessDepth, b.verdict.data());
    }
    if (settles()) {
      ccd_detail::fast_path_settle(kind, q, b.verdict.data(), ccd.toi_tolerance, b.settled.data(),
                                   b.toi.data());
    }
  }

  // A culled pair (by the NP filter, or by the distance filter after it) counts as culled by the
  // NP filter where ccd_hit counts it so: always for the separate filter and at a thickness,
  // with the fast path where the NP filter is on (counted_np). With the fast path (zero
  // thickness), the kept pairs that fast_path_settle settles are the kernel's misses on path
  // FastPath (nothing to count or report) and its certified hits (reported with the kernel's
  // time of impact).
  void flush_vf(FeatureBatch& b, FeatureCounters& c, std::vector<VertexFaceCollision>& out) const {
    flush_queries(ccd_detail::Kind::VertexFace, b.vf, b, c.vf_tests, c.vf_np,
                  [&](int i, double toi) {
                    const auto [v, f] = b.vf_ids[i];
                    out.push_back({v, f, topo->faces()[f], toi});
                  });
  }
  void flush_ee(FeatureBatch& b, FeatureCounters& c, std::vector<EdgeEdgeCollision>& out) const {
    flush_queries(ccd_detail::Kind::EdgeEdge, b.ee, b, c.ee_tests, c.ee_np, [&](int i, double toi) {
      const auto [ea, eb] = b.ee_ids[i];
      out.push_back({ea, eb, topo->edges()[ea], topo->edges()[eb], toi});
    });
  }

  // With the fast path on, the kernel starts with the same NP filter (one cubic, computed once);
  // without it the filter runs on its own first.
  [[nodiscard]] bool separate_np() const {
    return np_filter && ccd.thickness == 0 && !ccd.fast_path;
  }
  // With a thickness the cubic filter does not apply; the distance bound takes its place (it
  // culls resting contact, the bulk of a simulator's pairs): see distance_at_thickness().
  static CcdResult ccd_kernel(const VertexFaceQuery& q, const CcdOptions& o) {
    return vertex_face_ccd(q, o);
  }
  static CcdResult ccd_kernel(const EdgeEdgeQuery& q, const CcdOptions& o) {
    return edge_edge_ccd(q, o);
  }
  static CcdResult ccd_kernel_np_kept(const VertexFaceQuery& q, const CcdOptions& o) {
    return ccd_detail::vertex_face_ccd_np_kept(q, o);
  }
  static CcdResult ccd_kernel_np_kept(const EdgeEdgeQuery& q, const CcdOptions& o) {
    return ccd_detail::edge_edge_ccd_np_kept(q, o);
  }
  [[nodiscard]] bool counted_np(const CcdResult& r) const {
    return np_filter && r.path == CcdPath::NpCulled;
  }
};

/// DetectOptions::linked_vertices normalized for FeatureContext::links; throws InputError for an
/// id outside [0, num_vertices).
inline std::vector<std::pair<int, int>> sorted_links(const std::vector<std::pair<int, int>>& in,
                                                     int num_vertices) {
  std::vector<std::pair<int, int>> out;
  out.reserve(in.size());
  for (auto [a, b] : in) {
    if (a < 0 || b < 0 || a >= num_vertices || b >= num_vertices) {
      throw InputError(
          fmt::format("linked_vertices: pair ({}, {}) is outside 0..{}", a, b, num_vertices - 1));
    }
    if (a != b) out.emplace_back(std::min(a, b), std::max(a, b));
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// The context of a CCD step under `options` (thickness, filters, kernel settings; linked
/// vertices already normalized by sorted_links, or empty): the one place the options become
/// kernel settings, for the self and the two-mesh detectors and their oracles.
inline FeatureContext ccd_context(const Topology& topo, std::span<const Eigen::Vector3d> v0,
                                  std::span<const Eigen::Vector3d> v1, const DetectOptions& options,
                                  std::span<const std::pair<int, int>> links = {}) {
  FeatureContext ctx;
  ctx.topo = &topo;
  ctx.v0 = v0;
  ctx.v1 = v1;
  ctx.margin = 0.5 * options.thickness;
  ctx.np_filter = options.np_filter;
  ctx.zero_thickness_distance = options.distance_filter;
  ctx.ccd = CcdOptions{options.thickness, options.fast_path};
  ctx.ccd.toi_tolerance = options.toi_tolerance;
  ctx.distance_depth = options.distance_filter_depth;
  ctx.links = links;
  return ctx;
}

/// The context of a proximity query at distance h at positions v (boxes only: no kernel runs;
/// `links` as for ccd_context).
inline FeatureContext proximity_context(const Topology& topo, std::span<const Eigen::Vector3d> v,
                                        double h, std::span<const std::pair<int, int>> links = {}) {
  FeatureContext ctx;
  ctx.links = links;
  ctx.topo = &topo;
  ctx.v0 = v;
  ctx.v1 = v;
  ctx.margin = 0.5 * h;
  return ctx;
}

/// The swept boxes of every vertex, edge and face for one step, kept between steps: `update`
/// recomputes only the boxes of features with a vertex whose positions (t0 or t1) changed since
/// the last update with the same margin. A box depends on nothing else, so the result is the same
/// as recomputing all of them; a restricted CCD pass, in which a few hundred vertices of the
/// cloth changed their motion, then pays for those alone (the full recomputation was 90% of such
/// a pass on multilayer-rumba).
class FeatureBoxes {
 public:
  /// `face_blocks`: also keep each face's boxes gathered as a FaceBoxes (FeatureContext::
  /// face_boxes), for the pair loop of owned_feature_pairs.
  explicit FeatureBoxes(bool face_blocks = false) : blocks_on_(face_blocks) {}

  /// Brings the boxes up to date with ctx's positions and margin and points ctx at them. ctx's
  /// positions must be `step`'s current ones: when the boxes were last updated at the previous
  /// call of `step` with the same margin, only the features of its changed vertices are redone.
  void update(FeatureContext& ctx, const StepPositions& step) {
    const Topology& topo = *ctx.topo;
    const int nv = topo.num_vertices();
    std::span<const std::uint8_t> moved = step.changed_since(call_);
    if (margin_ != ctx.margin) moved = {};  // every box changes: start over
    margin_ = ctx.margin;
    call_ = step.call();
    if (moved.empty()) {
      vboxes_.resize(nv);
      eboxes_.resize(topo.num_edges());
      fboxes_.resize(topo.num_faces());
      if (blocks_on_) blocks_.resize(topo.num_faces());
    }
    const auto redo = [&](auto&& ids) {  // a vertex of the feature moved (or all did)
      if (moved.empty()) return true;
      for (int v : ids) {
        if (moved[v]) return true;
      }
      return false;
    };
    for_each(nv, [&](int i) {
      if (redo(std::array<int, 1>{i})) vboxes_[i] = ctx.compute_vertex_box(i);
    });
    // An edge's or face's box is the union of its vertices' boxes bit for bit: swept_feature_box's
    // rounding (minus the margin, next_down, to float downwards) is monotone, so the rounded
    // minimum of the points is the minimum of their rounded values (likewise upwards).
    for_each(topo.num_edges(), [&](int e) {
      if (redo(topo.edges()[e])) eboxes_[e] = merged(topo.edges()[e]);
    });
    for_each(topo.num_faces(), [&](int f) {
      if (redo(topo.faces()[f])) fboxes_[f] = merged(topo.faces()[f]);
    });
    if (blocks_on_) {
      // A face's block holds its own, its edges' and its corners' boxes: copies, redone exactly
      // when one of those is (a vertex of the face moved).
      for_each(topo.num_faces(), [&](int f) {
        const Face& t = topo.faces()[f];
        if (!redo(t)) return;
        FaceBoxes& b = blocks_[f];
        const auto edges = topo.face_edges(f);
        for (int k = 0; k < 3; ++k) {
          b.set(FaceBoxes::kEdges + k, eboxes_[edges[k]]);
          b.set(FaceBoxes::kCorners + k, vboxes_[t[k]]);
        }
        b.set(FaceBoxes::kFace, fboxes_[f]);
        b.set(7, fboxes_[f]);
      });
      ctx.face_boxes = blocks_;
    }
    ctx.vboxes = vboxes_;
    ctx.eboxes = eboxes_;
    ctx.fboxes = fboxes_;
  }

 private:
  template <class Ids>
  [[nodiscard]] Box merged(const Ids& ids) const {
    Box b = vboxes_[ids[0]];
    for (std::size_t k = 1; k < ids.size(); ++k) {
      const Box& o = vboxes_[ids[k]];
      for (int a = 0; a < 3; ++a) {
        b.lo[a] = std::min(b.lo[a], o.lo[a]);
        b.hi[a] = std::max(b.hi[a], o.hi[a]);
      }
    }
    return b;
  }

  template <class F>
  static void for_each(int n, F&& f) {
    tbb::parallel_for(tbb::blocked_range<int>(0, n, 4096), [&](const tbb::blocked_range<int>& r) {
      for (int i = r.begin(); i != r.end(); ++i)
        f(i);
    });
  }

  bool blocks_on_ = false;
  std::vector<Box> vboxes_, eboxes_, fboxes_;
  std::vector<FaceBoxes> blocks_;
  std::uint64_t call_ = 0;  // the StepPositions call the boxes were computed at (0: none)
  double margin_ = -1.0;
};

/// A hint to fetch the cache line holding `p` (no effect on results).
inline void prefetch(const void* p) {
#if defined(__GNUC__)
  __builtin_prefetch(p);
#else
  (void)p;
#endif
}

/// Procedural R-triangle of (v, f): the first face of v, ascending, that shares no vertex with f
/// (docs/algorithms.md 6.3); -1 when every face of v touches f (an orphan).
inline int vf_representative(const Topology& topo, int v, int f) {
  const Face& tf = topo.faces()[f];
  for (int g : topo.vertex_faces(v)) {
    if (!share_vertex(topo.faces()[g], tf)) return g;
  }
  return -1;
}

/// The first non-adjacent face pair (fa of ea, fb of eb) in a fixed order, ea < eb; {-1, -1} for an
/// orphan pair.
inline std::pair<int, int> ee_representative(const Topology& topo, int ea, int eb) {
  for (int fa : topo.edge_faces(ea)) {
    for (int fb : topo.edge_faces(eb)) {
      if (!share_vertex(topo.faces()[fa], topo.faces()[fb])) return {fa, fb};
    }
  }
  return {-1, -1};
}

/// The same R-triangle ownership answers as vf_representative / ee_representative, from per-face
/// and per-edge records and the topology's inline adjacency (no out-of-line calls in the narrow
/// phase's hot loop), for a triangle pair (f, g) that shares no vertex (the traversal drops the
/// others).
class Ownership {
 public:
  Ownership() = default;
  /// Keeps a pointer to `topo`, which must outlive it.
  explicit Ownership(const Topology& topo) : topo_(&topo) {
    // Every edge's and every face's record depends on the topology alone: filled in parallel.
    const auto for_each = [](int n, auto&& fn) {
      tbb::parallel_for(tbb::blocked_range<int>(0, n, 4096), [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i)
          fn(i);
      });
    };
    pair_.resize(topo.num_edges());
    for_each(topo.num_edges(), [&](int e) {
      const auto fs = topo.edge_faces(e);
      EdgeFaces& r = pair_[e];
      r.general = fs.size() > 2;
      for (std::size_t i = 0; i < 2; ++i) {
        r.f[i] = i < fs.size() ? fs[i] : -1;
        r.t[i] = i < fs.size() ? topo.faces()[fs[i]] : Face{-1, -1, -1};
      }
    });
    records_.resize(topo.num_faces());
    for_each(topo.num_faces(), [&](int f) {
      FaceRecord& r = records_[f];
      r.v = topo.faces()[f];
      r.e = topo.face_edges(f);
      r.first = 0;
      for (int k = 0; k < 3; ++k) {
        const int v = r.v[k];
        const int h = topo.vertex_faces(v)[0];
        if (h == f) r.first |= 1u << k;
        int n = 0;
        for (int x : topo.faces()[h]) {
          if (x != v) r.other[k][n++] = x;
        }
        const int he = topo.edge_faces(r.e[k])[0];
        if (he == f) r.first |= 8u << k;
        const Edge& d = topo.edges()[r.e[k]];
        for (int x : topo.faces()[he]) {
          if (x != d[0] && x != d[1]) r.apex[k] = x;
        }
      }
    });
  }

  /// One triangle's corners, edges and first-face data side by side (one cache line), so that the
  /// pair loop reads one record per triangle and settles ownership from the two records alone
  /// but for a few pairs (owned_feature_pairs).
  struct alignas(64) FaceRecord {
    Face v;                // corners
    std::array<int, 3> e;  // face_edges: edge k joins corners k and (k + 1) % 3
    // The two corners other than v[k] of v[k]'s first face.
    int other[3][2];
    // The corner off edge e[k] of that edge's first face.
    int apex[3];
    // Bit k (0..2): this face is the first face of corner k; bit 3 + k: the first face of edge
    // e[k]. The first face of v owns (v, g) for every g it shares no vertex with, and two first
    // faces own their edges' pair (both searches stop at their first step): in a manifold mesh
    // most features are tested by their first face, so one bit test replaces the searches.
    std::uint8_t first;

    /// Edge e[k]'s vertices as Topology::edges() lists them (smaller id first).
    [[nodiscard]] Edge edge(int k) const {
      const int a = v[k], b = v[k == 2 ? 0 : k + 1];
      return a < b ? Edge{a, b} : Edge{b, a};
    }
  };

  [[nodiscard]] const FaceRecord& record(int f) const { return records_[f]; }

  /// Whether f (a face of v, sharing no vertex with g) is the R-triangle of (v, g): every face of
  /// v before it touches g.
  [[nodiscard]] bool owns_vf(int v, int g, int f) const {
    const auto& faces = topo_->faces();
    const Face& tg = faces[g];
    for (int h : topo_->vertex_faces(v)) {
      if (h == f) return true;
      if (!share_vertex(faces[h], tg)) return false;
    }
    return false;
  }

  /// Whether (x, y) (x a face of e1, y of e2, sharing no vertex) is the first non-adjacent face
  /// pair of (e1, e2) in ee_representative's order.
  [[nodiscard]] bool owns_ee(int e1, int e2, int x, int y) const {
    const EdgeFaces& a = pair_[e1];
    const EdgeFaces& b = pair_[e2];
    if (a.general || b.general) return owns_ee_general(e1, e2, x, y);
    // The same search over the copies (at most two faces per edge, in edge_faces order).
    for (int i = 0; i < 2 && a.f[i] >= 0; ++i) {
      for (int j = 0; j < 2 && b.f[j] >= 0; ++j) {
        if (a.f[i] == x && b.f[j] == y) return true;
        if (!share_vertex(a.t[i], b.t[j])) return false;
      }
    }
    return false;
  }

 private:
  // An edge's (first two) faces and their corners side by side: the search touches one record
  // per edge instead of the offset, id and face arrays.
  struct EdgeFaces {
    int f[2];  // -1 past the edge's faces
    Face t[2];
    bool general;  // more than two faces: use owns_ee_general
  };

  [[nodiscard]] bool owns_ee_general(int e1, int e2, int x, int y) const {
    const auto& faces = topo_->faces();
    for (int fa : topo_->edge_faces(e1)) {
      for (int fb : topo_->edge_faces(e2)) {
        if (fa == x && fb == y) return true;
        if (!share_vertex(faces[fa], faces[fb])) return false;
      }
    }
    return false;
  }

  const Topology* topo_ = nullptr;
  std::vector<EdgeFaces> pair_;
  std::vector<FaceRecord> records_;
};

/// Which feature boxes of a triangle pair (f, g) overlap, in owned_feature_pairs' terms: bit k
/// of `vf_f` vertex k of f against face g; of `vf_g` vertex k of g against face f; bit 3 i + j of
/// `ee` edge i of f against edge j of g, set only where edge i of f also overlaps face g (the
/// scalar test looks at the edge pairs of such edges alone).
struct FeatureOverlaps {
  unsigned vf_f = 0, vf_g = 0, ee = 0;
  bool operator==(const FeatureOverlaps&) const = default;
};

/// A step's precomputed swept boxes (FeatureContext::vboxes, eboxes, fboxes) for
/// owned_feature_pairs, one box test at a time.
struct StepBoxes {
  const FeatureContext& ctx;
  [[nodiscard]] const Box& vertex(int v) const { return ctx.vboxes[v]; }
  [[nodiscard]] const Box& edge(int e) const { return ctx.eboxes[e]; }
  [[nodiscard]] const Box& face(int f) const { return ctx.fboxes[f]; }

  /// The overlaps of (f, g), whose records are rf and rg.
  template <class Record>
  [[nodiscard]] FeatureOverlaps overlaps(const Record& rf, const Record& rg, int f, int g) const {
    const Box& bf = face(f);
    const Box& bg = face(g);
    FeatureOverlaps o;
    for (int k = 0; k < 3; ++k) {
      o.vf_f |= unsigned(overlap(vertex(rf.v[k]), bg)) << k;
      o.vf_g |= unsigned(overlap(vertex(rg.v[k]), bf)) << k;
    }
    for (int i = 0; i < 3; ++i) {
      const Box& ba = edge(rf.e[i]);
      if (!overlap(ba, bg)) continue;  // edge of f misses all of g
      for (int j = 0; j < 3; ++j)
        o.ee |= unsigned(overlap(ba, edge(rg.e[j]))) << (3 * i + j);
    }
    return o;
  }
};

/// feature_overlaps lane by lane: the same float comparisons as StepBoxes::overlaps, on the
/// copies of the same boxes (the reference the vector form is tested against).
inline FeatureOverlaps feature_overlaps_scalar(const FaceBoxes& a, const FaceBoxes& b) {
  FeatureOverlaps o;
  const Box fa = a.face(), fb = b.face();
  for (int k = 0; k < 3; ++k) {
    o.vf_f |= unsigned(overlap(a.get(FaceBoxes::kCorners + k), fb)) << k;
    o.vf_g |= unsigned(overlap(b.get(FaceBoxes::kCorners + k), fa)) << k;
  }
  for (int i = 0; i < 3; ++i) {
    const Box ea = a.get(FaceBoxes::kEdges + i);
    if (!overlap(ea, fb)) continue;
    for (int j = 0; j < 3; ++j)
      o.ee |= unsigned(overlap(ea, b.get(FaceBoxes::kEdges + j))) << (3 * i + j);
  }
  return o;
}

/// The overlaps of a triangle pair from the faces' blocks a (of f) and b (of g): StepBoxes::
/// overlaps' answer exactly. The blocks hold copies of the same float boxes, and each lane
/// makes the same two comparisons per axis as overlap(FeatureBox, FeatureBox), lo <= hi of the
/// other box both ways (ordered, so false on NaN as the scalar `<=`), ANDed over the axes; the
/// scalar form's skipped edge pairs (edge of f missing face g) are masked off. On SSE2, 4 lanes:
/// f's edges and face against g's face, f's corners against g's face, g's corners against f's
/// face, and each edge of f against g's edges.
[[gnu::always_inline]] inline FeatureOverlaps feature_overlaps(const FaceBoxes& a,
                                                               const FaceBoxes& b) {
#if defined(__SSE2__)
  const __m128 ones = _mm_castsi128_ps(_mm_set1_epi32(-1));
  __m128 ae = ones, av = ones, bv = ones;  // f's edges vs g's face; f's / g's corners vs face
  __m128 ee[3] = {ones, ones, ones};       // edge i of f vs g's edges
  for (int c = 0; c < 3; ++c) {
    const __m128 alo = _mm_load_ps(a.lo[c]), ahi = _mm_load_ps(a.hi[c]);
    const __m128 blo = _mm_load_ps(b.lo[c]), bhi = _mm_load_ps(b.hi[c]);
    const __m128 avlo = _mm_load_ps(a.lo[c] + 4), avhi = _mm_load_ps(a.hi[c] + 4);
    const __m128 bvlo = _mm_load_ps(b.lo[c] + 4), bvhi = _mm_load_ps(b.hi[c] + 4);
    const __m128 aflo = _mm_shuffle_ps(alo, alo, _MM_SHUFFLE(3, 3, 3, 3));
    const __m128 afhi = _mm_shuffle_ps(ahi, ahi, _MM_SHUFFLE(3, 3, 3, 3));
    const __m128 bflo = _mm_shuffle_ps(blo, blo, _MM_SHUFFLE(3, 3, 3, 3));
    const __m128 bfhi = _mm_shuffle_ps(bhi, bhi, _MM_SHUFFLE(3, 3, 3, 3));
    ae = _mm_and_ps(ae, _mm_and_ps(_mm_cmple_ps(alo, bfhi), _mm_cmple_ps(bflo, ahi)));
    av = _mm_and_ps(av, _mm_and_ps(_mm_cmple_ps(avlo, bfhi), _mm_cmple_ps(bflo, avhi)));
    bv = _mm_and_ps(bv, _mm_and_ps(_mm_cmple_ps(bvlo, afhi), _mm_cmple_ps(aflo, bvhi)));
    const __m128 lo0 = _mm_shuffle_ps(alo, alo, _MM_SHUFFLE(0, 0, 0, 0));
    const __m128 hi0 = _mm_shuffle_ps(ahi, ahi, _MM_SHUFFLE(0, 0, 0, 0));
    const __m128 lo1 = _mm_shuffle_ps(alo, alo, _MM_SHUFFLE(1, 1, 1, 1));
    const __m128 hi1 = _mm_shuffle_ps(ahi, ahi, _MM_SHUFFLE(1, 1, 1, 1));
    const __m128 lo2 = _mm_shuffle_ps(alo, alo, _MM_SHUFFLE(2, 2, 2, 2));
    const __m128 hi2 = _mm_shuffle_ps(ahi, ahi, _MM_SHUFFLE(2, 2, 2, 2));
    ee[0] = _mm_and_ps(ee[0], _mm_and_ps(_mm_cmple_ps(lo0, bhi), _mm_cmple_ps(blo, hi0)));
    ee[1] = _mm_and_ps(ee[1], _mm_and_ps(_mm_cmple_ps(lo1, bhi), _mm_cmple_ps(blo, hi1)));
    ee[2] = _mm_and_ps(ee[2], _mm_and_ps(_mm_cmple_ps(lo2, bhi), _mm_cmple_ps(blo, hi2)));
  }
  const unsigned edges = static_cast<unsigned>(_mm_movemask_ps(ae));
  FeatureOverlaps o;
  o.vf_f = static_cast<unsigned>(_mm_movemask_ps(av)) & 7u;
  o.vf_g = static_cast<unsigned>(_mm_movemask_ps(bv)) & 7u;
  for (int i = 0; i < 3; ++i) {
    const unsigned row = static_cast<unsigned>(_mm_movemask_ps(ee[i])) & 7u;
    o.ee |= (((edges >> i) & 1u) != 0 ? row : 0u) << (3 * i);
  }
  return o;
#else
  return feature_overlaps_scalar(a, b);
#endif
}

/// A step's boxes gathered per face (FeatureContext::face_boxes) for owned_feature_pairs: the
/// same overlaps as StepBoxes, several box tests per instruction.
struct StepFaceBoxes {
  const FeatureContext& ctx;
  template <class Record>
  [[nodiscard, gnu::always_inline]] FeatureOverlaps overlaps(const Record&, const Record&, int f,
                                                             int g) const {
    return feature_overlaps(ctx.face_boxes[f], ctx.face_boxes[g]);
  }
};

/// No geometry for owned_feature_pairs: every box overlaps every other, so it yields every
/// feature pair the triangle pair owns.
struct NoBoxes {
  template <class Record>
  [[nodiscard]] FeatureOverlaps overlaps(const Record&, const Record&, int, int) const {
    return {7u, 7u, 0x1ffu};
  }
};

/// Whether x is a corner of t.
inline bool has_corner(const Face& t, int x) {
  return x == t[0] || x == t[1] || x == t[2];
}

/// Bit 3 i + j set for every i in `rows` and j in `cols` (3-bit masks).
inline unsigned outer_bits(unsigned rows, unsigned cols) {
  static constexpr unsigned short kRows[8] = {0x000, 0x007, 0x038, 0x03f,
                                              0x1c0, 0x1c7, 0x1f8, 0x1ff};
  return kRows[rows & 7u] & ((cols & 7u) * 0x49u);  // cols repeated at bits 0, 3, 6
}

/// Where ownership of a triangle pair (f, g)'s feature pairs needs the ordered search, in
/// FeatureOverlaps' bit layout, from the faces' records rf and rg (see owned_feature_pairs): VF
/// bit k, when a corner of g (of f) is one of the two other corners of the first face of f's (g's)
/// corner k; EE bit 3 i + j, when the apex wb of edge j of g is a corner of f, the apex wa of edge
/// i of f a corner of g, or wa == wb. Lane by lane, the reference of search_masks.
inline FeatureOverlaps search_masks_scalar(const Ownership::FaceRecord& rf,
                                           const Ownership::FaceRecord& rg) {
  FeatureOverlaps m;
  for (int k = 0; k < 3; ++k) {
    m.vf_f |= unsigned(has_corner(rg.v, rf.other[k][0]) || has_corner(rg.v, rf.other[k][1])) << k;
    m.vf_g |= unsigned(has_corner(rf.v, rg.other[k][0]) || has_corner(rf.v, rg.other[k][1])) << k;
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const int wa = rf.apex[i], wb = rg.apex[j];
      m.ee |= unsigned(has_corner(rf.v, wb) || has_corner(rg.v, wa) || wa == wb) << (3 * i + j);
    }
  }
  return m;
}

#if defined(__SSE2__)
namespace simd {
// Four ints of record r from word `word` on.
[[gnu::always_inline]] inline __m128i words(const Ownership::FaceRecord& r, int word) {
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(reinterpret_cast<const int*>(&r) + word));
}
// One bit per lane (its sign bit).
[[gnu::always_inline]] inline unsigned lane_bits(__m128i x) {
  return static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(x)));
}
// Bit k: lane 2 k or 2 k + 1 set, of lanes 0..3 in m01 and 4..5 in m2 (lanes 0..1 there).
[[gnu::always_inline]] inline unsigned either_of_pairs(unsigned m01, unsigned m2) {
  return unsigned((m01 & 3u) != 0) | unsigned((m01 & 12u) != 0) << 1 |
         unsigned((m2 & 3u) != 0) << 2;
}
}  // namespace simd
#endif

/// search_masks_scalar with SSE2 integer compares: each corner of one face against the other
/// face's first-face corners and apexes four at a time, the apexes against each other by rows.
/// Equality of ints, so the same bits.
[[gnu::always_inline]] inline FeatureOverlaps search_masks(const Ownership::FaceRecord& rf,
                                                           const Ownership::FaceRecord& rg) {
#if defined(__SSE2__)
  static_assert(offsetof(Ownership::FaceRecord, other) == 24 &&
                offsetof(Ownership::FaceRecord, apex) == 48 && sizeof(Ownership::FaceRecord) == 64);
  // Words 0..3: v[0..2], e[0]; 6..9: other[0], other[1]; 10..13: other[2], apex[0..1];
  // 12..15: apex[0..2], first. Lanes past the fields are masked off below.
  using simd::lane_bits, simd::words;
  const __m128i vf = words(rf, 0), vg = words(rg, 0);
  const __m128i of01 = words(rf, 6), of2 = words(rf, 10), af = words(rf, 12);
  const __m128i og01 = words(rg, 6), og2 = words(rg, 10), ag = words(rg, 12);
  __m128i tf01 = _mm_setzero_si128(), tf2 = tf01, taf = tf01;  // ... equals a corner of g
  __m128i tg01 = tf01, tg2 = tf01, tag = tf01;                 // ... equals a corner of f
  const __m128i corners_g[3] = {_mm_shuffle_epi32(vg, 0x00), _mm_shuffle_epi32(vg, 0x55),
                                _mm_shuffle_epi32(vg, 0xaa)};
  const __m128i corners_f[3] = {_mm_shuffle_epi32(vf, 0x00), _mm_shuffle_epi32(vf, 0x55),
                                _mm_shuffle_epi32(vf, 0xaa)};
  for (int c = 0; c < 3; ++c) {
    const __m128i cg = corners_g[c], cf = corners_f[c];
    tf01 = _mm_or_si128(tf01, _mm_cmpeq_epi32(of01, cg));
    tf2 = _mm_or_si128(tf2, _mm_cmpeq_epi32(of2, cg));
    taf = _mm_or_si128(taf, _mm_cmpeq_epi32(af, cg));
    tg01 = _mm_or_si128(tg01, _mm_cmpeq_epi32(og01, cf));
    tg2 = _mm_or_si128(tg2, _mm_cmpeq_epi32(og2, cf));
    tag = _mm_or_si128(tag, _mm_cmpeq_epi32(ag, cf));
  }
  FeatureOverlaps m;
  m.vf_f = simd::either_of_pairs(lane_bits(tf01), lane_bits(tf2));
  m.vf_g = simd::either_of_pairs(lane_bits(tg01), lane_bits(tg2));
  const unsigned same = (lane_bits(_mm_cmpeq_epi32(ag, _mm_shuffle_epi32(af, 0x00))) & 7u) |
                        (lane_bits(_mm_cmpeq_epi32(ag, _mm_shuffle_epi32(af, 0x55))) & 7u) << 3 |
                        (lane_bits(_mm_cmpeq_epi32(ag, _mm_shuffle_epi32(af, 0xaa))) & 7u) << 6;
  m.ee = outer_bits(lane_bits(taf) & 7u, 7u) | outer_bits(7u, lane_bits(tag) & 7u) | same;
  return m;
#else
  return search_masks_scalar(rf, rg);
#endif
}

/// The feature pairs of the triangle pair (f, g), sharing no vertex, whose R-triangle pair it is
/// (docs/algorithms.md 6.3) and whose boxes overlap: vf(v, face, corners of face) for a vertex of
/// one face against the other, ee(e1, e2, vertices of e1, vertices of e2) with e1 < e2 for an edge
/// of each. Box tests first (cheap, they reject most: `boxes.overlaps`, see FeatureOverlaps),
/// then ownership from the faces' records: a set bit of `first` settles it; otherwise the first
/// candidate of the ordered search owns the pair, and it is not (f, g), unless that candidate
/// touches the other face, and the records tell when it can (search_masks):
///  - VF (v of f, against g): the search starts at v's first face h, which is not f. h holds v,
///    which g lacks, so h touches g exactly when one of h's other two corners is in g.
///  - EE (edge a of f, edge b of g): the search starts at the edges' first faces ha = a + wa and
///    hb = b + wb (wa, wb the apexes). a and b lie in f and g, which share no vertex, so ha and hb
///    share one only if wb is in f, wa is in g or wa == wb. Where f is ha itself, wa is f's third
///    corner (not in g) and the test is exactly "wb in f"; likewise for g.
/// Only when the candidate may touch does the ordered search run (owns_vf, owns_ee).
template <class Boxes, class Vf, class Ee>
void owned_feature_pairs(const Ownership& owner, const Boxes& boxes, int f, int g, Vf&& vf,
                         Ee&& ee) {
  const Ownership::FaceRecord& rf = owner.record(f);
  const Ownership::FaceRecord& rg = owner.record(g);
  const FeatureOverlaps o = boxes.overlaps(rf, rg, f, g);
  if ((o.vf_f | o.vf_g | o.ee) == 0) return;
  const FeatureOverlaps search = search_masks(rf, rg);
  const unsigned mf = rf.first, mg = rg.first;
  // Owned outright: first faces of the vertex, of both edges.
  const unsigned first_ee = outer_bits((mf >> 3) & 7u, (mg >> 3) & 7u);
  for (unsigned bits = o.vf_f & ((mf & 7u) | search.vf_f); bits != 0; bits &= bits - 1) {
    const int k = std::countr_zero(bits);
    const int v = rf.v[k];
    if (!((mf >> k) & 1u) && !owner.owns_vf(v, g, f)) continue;
    vf(v, g, rg.v);
  }
  for (unsigned bits = o.vf_g & ((mg & 7u) | search.vf_g); bits != 0; bits &= bits - 1) {
    const int k = std::countr_zero(bits);
    const int v = rg.v[k];
    if (!((mg >> k) & 1u) && !owner.owns_vf(v, f, g)) continue;
    vf(v, f, rf.v);
  }
  for (unsigned bits = o.ee & (first_ee | search.ee); bits != 0; bits &= bits - 1) {
    const int n = std::countr_zero(bits);
    const int i = n / 3, j = n % 3;
    const int ea = rf.e[i], eb = rg.e[j];
    const bool a_first = ea < eb;
    const int e1 = a_first ? ea : eb, e2 = a_first ? eb : ea;
    if (!((first_ee >> n) & 1u) &&
        !(a_first ? owner.owns_ee(e1, e2, f, g) : owner.owns_ee(e1, e2, g, f))) {
      continue;
    }
    if (a_first) {
      ee(e1, e2, rf.edge(i), rg.edge(j));
    } else {
      ee(e1, e2, rg.edge(j), rf.edge(i));
    }
  }
}

inline bool vf_less(const VertexFaceCollision& a, const VertexFaceCollision& b) {
  return a.vertex < b.vertex || (a.vertex == b.vertex && a.face < b.face);
}
inline bool ee_less(const EdgeEdgeCollision& a, const EdgeEdgeCollision& b) {
  return a.edge_a < b.edge_a || (a.edge_a == b.edge_a && a.edge_b < b.edge_b);
}

}  // namespace clothcd::detail
