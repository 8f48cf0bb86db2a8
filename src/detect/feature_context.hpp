#pragma once
// The settings and positions of one step (FeatureContext): the one place the options become the
// filters and kernels every VF and EE pair goes through, for the detectors and their oracles.

#include "detect/feature_batches.hpp"

namespace clothcd::detail {

/// A filter that feature queries go through before the kernel, in this order of its steps.
enum class FeatureFilter : std::uint8_t {
  None,        // the kernel decides alone
  Np,          // the cubic NP filter (zero thickness)
  NpDistance,  // the NP filter, then the distance filter on what it keeps (zero thickness)
  Distance,    // the distance filter at the thickness
};

/// The filter pipeline of one pass, resolved once from the options (filter_plan): what the
/// triangle pairs and the feature pairs go through before the kernels. The pair loop and the
/// batches switch on it; a query tested alone (ccd_hit) runs `single`, a batch `batch`, with the
/// same verdicts, counts and times of impact.
struct FilterPlan {
  bool faces_apart = false;  // triangle pairs through the whole-triangle distance bound first
  FeatureFilter single = FeatureFilter::None;  // a query alone, before its kernel
  // A batch of queries; at zero thickness with the fast path, the NP filter that the kernel
  // would start with (its culls counted only where np_filter is on).
  FeatureFilter batch = FeatureFilter::None;
  bool settle = false;     // the batch settles queries with the zero-thickness kernel's search
  bool count_np = false;   // filter culls count as NP culls (DetectOptions::np_filter)
  bool kernel = true;      // false: every pair the filters keep is a hit at time 0
  int distance_depth = 0;  // bisections of the distance filter at a thickness

  friend bool operator==(const FilterPlan&, const FilterPlan&) = default;
};

/// Bisections of the distance filter at zero thickness: on cloth_ball 92 -> 93 it culls 44% of
/// the pairs the NP filter keeps at depth 0, 80% at depth 2, each a search the fast path is
/// spared; deeper costs more than its further culls save.
inline constexpr int kZeroThicknessDepth = 2;

/// The pipeline of DetectOptions' thickness, np_filter, distance_filter (and its depth) and
/// fast_path. With a thickness the cubic NP filter does not apply: the distance bound takes its
/// place (it culls resting contact, the bulk of a simulator's pairs). At zero thickness the
/// distance filter runs on what the NP filter keeps, with distance_filter.
[[nodiscard]] inline FilterPlan filter_plan(double thickness, bool np_filter, bool distance_filter,
                                            bool fast_path, int distance_depth) {
  FilterPlan p;
  p.faces_apart = np_filter && (thickness > 0 || distance_filter);
  p.count_np = np_filter;
  p.distance_depth = distance_depth;
  if (thickness > 0) {
    p.single = p.batch = np_filter ? FeatureFilter::Distance : FeatureFilter::None;
    return p;
  }
  const FeatureFilter np =
      np_filter && distance_filter ? FeatureFilter::NpDistance : FeatureFilter::Np;
  // With the fast path the kernel starts with the same NP filter (one cubic, computed once), so
  // a query alone runs the separate one only where the distance filter follows it.
  p.single = !np_filter                             ? FeatureFilter::None
             : fast_path && np == FeatureFilter::Np ? FeatureFilter::None
                                                    : np;
  p.batch = np_filter || fast_path ? np : FeatureFilter::None;
  p.settle = fast_path;
  return p;
}

/// Positions of one step and the test settings.
struct FeatureContext {
  const Topology* topo = nullptr;
  std::span<const Eigen::Vector3d> v0, v1;
  double margin = 0;  // thickness / 2
  FilterPlan plan;
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
  // The precomputed boxes where there are any: the arrays, else the face blocks (a vertex's or
  // an edge's box from its first face's block; the same bits), else computed.
  [[nodiscard]] Box face_box(int f) const {
    if (!fboxes.empty()) return fboxes[f];
    return face_boxes.empty() ? compute_face_box(f) : face_boxes[f].face();
  }
  [[nodiscard]] Box vertex_box(int v) const {
    if (!vboxes.empty()) return vboxes[v];
    const auto faces = topo->vertex_faces(v);
    if (face_boxes.empty() || faces.empty()) return compute_vertex_box(v);
    const Face& t = topo->faces()[faces[0]];
    const int k = t[0] == v ? 0 : t[1] == v ? 1 : 2;
    return face_boxes[faces[0]].get(FaceBoxes::kCorners + k);
  }
  [[nodiscard]] Box edge_box(int e) const {
    if (!eboxes.empty()) return eboxes[e];
    if (face_boxes.empty()) return compute_edge_box(e);
    const int h = topo->edge_faces(e)[0];
    const auto& fe = topo->face_edges(h);
    const int k = fe[0] == e ? 0 : fe[1] == e ? 1 : 2;
    return face_boxes[h].get(FaceBoxes::kEdges + k);
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
  /// counts them, the others go through kernel_vf's path (all of them where the plan has no
  /// batch filter). `flush` tests what is left.
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
  /// they keep (without a batch filter in the plan, ccd_hit's own path one query at a time). Counts
  /// each query in `tests` and a filter's cull in `culled`; calls hit(i, toi) for each query i that
  /// collides. The same verdicts, counts and times of impact as ccd_hit one query at a time.
  template <class Hit>
  void flush_queries(ccd_detail::Kind kind, ccd_detail::NpBatch& q, FeatureBatch& b,
                     std::uint64_t& tests, std::uint64_t& culled, Hit&& hit) const {
    if (q.size == 0) return;
    filter_batch(kind, q, b);
    for (int i = 0; i < q.size; ++i) {
      ++tests;
      if (b.verdict[i] == ccd_detail::NpVerdict::Culled) {
        culled += plan.count_np ? 1 : 0;
        continue;
      }
      if (plan.settle && b.settled[i] != ccd_detail::FastSettled::Run) {  // the kernel's own answer
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

 private:
  // ccd_hit without counting the test. `kept`: the batch's filters have kept q already (at zero
  // thickness unscaled_np_filter's verdict is Kept, then np_filter_culls is false and the kernel
  // need not run that filter again; at a thickness the distance filter has not culled it).
  template <class Query>
  bool ccd_test(const Query& q, std::uint64_t& culled, double& toi, bool kept = false) const {
    if (!kept && single_filter_culls(q)) {
      ++culled;
      return false;
    }
    if (!plan.kernel) {
      toi = 0;
      return true;
    }
    const CcdResult r =
        kept && ccd.thickness == 0 ? ccd_kernel_np_kept(q, ccd) : ccd_kernel(q, ccd);
    culled += plan.count_np && r.path == CcdPath::NpCulled ? 1 : 0;
    if (r.hit) toi = r.toi;
    return r.hit;
  }

  // The plan's filter for a query alone (plan.single).
  template <class Query>
  [[nodiscard]] bool single_filter_culls(const Query& q) const {
    switch (plan.single) {
      case FeatureFilter::None:
        return false;
      case FeatureFilter::Np:
        return np_filter_culls(q);
      case FeatureFilter::NpDistance:
        return np_filter_culls(q) || distance_filter_culls(q, 0.0, kZeroThicknessDepth);
      case FeatureFilter::Distance:
        return distance_filter_culls(q, ccd.thickness, plan.distance_depth);
    }
    return false;
  }

  // The batch's filters (plan.batch), then with plan.settle the kernel's own search down to
  // kSettleLevel. Without a batch filter every verdict is Undecided (ccd_test decides); at a
  // thickness every query starts Kept.
  void filter_batch(ccd_detail::Kind kind, const ccd_detail::NpBatch& q, FeatureBatch& b) const {
    switch (plan.batch) {
      case FeatureFilter::None:
        std::fill_n(b.verdict.begin(), q.size, ccd_detail::NpVerdict::Undecided);
        return;
      case FeatureFilter::Distance:
        std::fill_n(b.verdict.begin(), q.size, ccd_detail::NpVerdict::Kept);
        ccd_detail::distance_filter_batch(kind, q, ccd.thickness, plan.distance_depth,
                                          b.verdict.data());
        return;
      case FeatureFilter::Np:
      case FeatureFilter::NpDistance:
        ccd_detail::np_filter_batch(kind, q, b.verdict.data());
        if (plan.batch == FeatureFilter::NpDistance) {
          ccd_detail::distance_filter_batch(kind, q, 0.0, kZeroThicknessDepth, b.verdict.data());
        }
        break;
    }
    if (plan.settle) {
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
  ctx.plan = filter_plan(options.thickness, options.np_filter, options.distance_filter,
                         options.fast_path, options.distance_filter_depth);
  ctx.ccd = CcdOptions{options.thickness, options.fast_path};
  ctx.ccd.toi_tolerance = options.toi_tolerance;
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

}  // namespace clothcd::detail
