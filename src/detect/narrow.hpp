#pragma once
// Feature-level tests shared by the detector and the brute-force oracle, so both put every VF and
// EE pair through exactly the same box test, NP filter and kernel.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "clothcd/ccd/queries.hpp"
#include "clothcd/detect/types.hpp"

namespace clothcd::detail {

struct Box {
  Eigen::Vector3d lo, hi;
};

inline Box swept_box(std::initializer_list<const Eigen::Vector3d*> pts, double margin) {
  Box b{Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
        Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity())};
  for (const Eigen::Vector3d* p : pts) {
    b.lo = b.lo.cwiseMin(*p);
    b.hi = b.hi.cwiseMax(*p);
  }
  if (margin > 0) {
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = std::nextafter(b.lo[k] - margin, -std::numeric_limits<double>::infinity());
      b.hi[k] = std::nextafter(b.hi[k] + margin, std::numeric_limits<double>::infinity());
    }
  }
  return b;
}

inline bool overlap(const Box& a, const Box& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

inline bool share_vertex(const Face& a, const Face& b) {
  for (int x : a) {
    if (x == b[0] || x == b[1] || x == b[2]) return true;
  }
  return false;
}

/// Per-thread counters of the feature tests.
struct FeatureCounters {
  std::uint64_t vf_tests = 0, ee_tests = 0, vf_np = 0, ee_np = 0;
};

/// Positions of one step and the test settings.
struct FeatureContext {
  const Topology* topo = nullptr;
  std::span<const Eigen::Vector3d> v0, v1;
  double margin = 0;  // thickness / 2
  bool np_filter = true;
  CcdOptions ccd;
  /// Optional swept boxes of every vertex, edge and face for this step (`precompute_boxes`);
  /// empty: computed on demand.
  std::span<const Box> vboxes, eboxes, fboxes;

  [[nodiscard]] Box compute_face_box(int f) const {
    const Face& t = topo->faces()[f];
    return swept_box({&v0[t[0]], &v0[t[1]], &v0[t[2]], &v1[t[0]], &v1[t[1]], &v1[t[2]]}, margin);
  }
  [[nodiscard]] Box compute_vertex_box(int v) const { return swept_box({&v0[v], &v1[v]}, margin); }
  [[nodiscard]] Box compute_edge_box(int e) const {
    const Edge& d = topo->edges()[e];
    return swept_box({&v0[d[0]], &v0[d[1]], &v1[d[0]], &v1[d[1]]}, margin);
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

  /// Vertex v against face f (their boxes already overlap): NP filter, then the kernel.
  void kernel_vf(int v, int f, FeatureCounters& c, std::vector<VertexFaceCollision>& out) const {
    ++c.vf_tests;
    const Face& t = topo->faces()[f];
    const VertexFaceQuery q{v0[v], v0[t[0]], v0[t[1]], v0[t[2]],
                            v1[v], v1[t[0]], v1[t[1]], v1[t[2]]};
    if (separate_np() && np_filter_culls(q)) {
      ++c.vf_np;
      return;
    }
    const CcdResult r = vertex_face_ccd(q, ccd);
    c.vf_np += counted_np(r);
    if (r.hit) out.push_back({v, f, t, r.toi});
  }

  /// Edges ea < eb (their boxes already overlap).
  void kernel_ee(int ea, int eb, FeatureCounters& c, std::vector<EdgeEdgeCollision>& out) const {
    ++c.ee_tests;
    const Edge& a = topo->edges()[ea];
    const Edge& b = topo->edges()[eb];
    const EdgeEdgeQuery q{v0[a[0]], v0[a[1]], v0[b[0]], v0[b[1]],
                          v1[a[0]], v1[a[1]], v1[b[0]], v1[b[1]]};
    if (separate_np() && np_filter_culls(q)) {
      ++c.ee_np;
      return;
    }
    const CcdResult r = edge_edge_ccd(q, ccd);
    c.ee_np += counted_np(r);
    if (r.hit) out.push_back({ea, eb, a, b, r.toi});
  }

 private:
  // With the fast path on, the kernel starts with the same NP filter (one cubic, computed once);
  // without it the filter runs on its own first.
  [[nodiscard]] bool separate_np() const {
    return np_filter && ccd.thickness == 0 && !ccd.fast_path;
  }
  [[nodiscard]] bool counted_np(const CcdResult& r) const {
    return np_filter && r.path == CcdPath::np_culled;
  }
};

/// Fills the context's box arrays for this step (in parallel), reusing the given storage: each
/// box is then computed once per step instead of once per triangle pair that needs it.
inline void precompute_boxes(FeatureContext& ctx, std::vector<Box>& vboxes,
                             std::vector<Box>& eboxes, std::vector<Box>& fboxes) {
  ctx.vboxes = {};
  ctx.eboxes = {};
  ctx.fboxes = {};
  vboxes.resize(ctx.topo->num_vertices());
  eboxes.resize(ctx.topo->num_edges());
  fboxes.resize(ctx.topo->num_faces());
  auto fill = [](std::vector<Box>& out, auto&& compute) {
    tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(out.size()), 4096),
                      [&](const tbb::blocked_range<int>& r) {
                        for (int i = r.begin(); i != r.end(); ++i)
                          out[i] = compute(i);
                      });
  };
  fill(vboxes, [&](int i) { return ctx.compute_vertex_box(i); });
  fill(eboxes, [&](int i) { return ctx.compute_edge_box(i); });
  fill(fboxes, [&](int i) { return ctx.compute_face_box(i); });
  ctx.vboxes = vboxes;
  ctx.eboxes = eboxes;
  ctx.fboxes = fboxes;
}

/// Procedural R-triangle of (v, f): the first face of v, ascending, that shares no vertex with f
/// (algorithms.md 6.3); -1 when every face of v touches f (an orphan).
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

inline bool vf_less(const VertexFaceCollision& a, const VertexFaceCollision& b) {
  return a.vertex < b.vertex || (a.vertex == b.vertex && a.face < b.face);
}
inline bool ee_less(const EdgeEdgeCollision& a, const EdgeEdgeCollision& b) {
  return a.edge_a < b.edge_a || (a.edge_a == b.edge_a && a.edge_b < b.edge_b);
}

}  // namespace clothcd::detail
