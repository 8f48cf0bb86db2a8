// Brute-force references: every feature pair through the detectors' own feature tests.

#include "clothcd/research/oracle.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "detect/narrow.hpp"
#include "detect/pair_results.hpp"
#include "detect/positions.hpp"

namespace clothcd::research {
namespace {

struct Buffer {
  detail::FeatureCounters c;
  std::vector<VertexFaceCollision> vf;
  std::vector<EdgeEdgeCollision> ee;
};

// The two-mesh oracle's buffer: A's vertices on B's faces, B's on A's, the edge pairs.
struct PairBuffer {
  detail::FeatureCounters c;
  std::vector<VertexFaceCollision> ab, ba;
  std::vector<EdgeEdgeCollision> ee;
};

// CCD of vertex v of side `sv` against face f of side `sf`, with the context `k`'s settings.
bool vf_hit(const detail::FeatureContext& k, const detail::FeatureContext& sv, int v,
            const detail::FeatureContext& sf, int f, detail::FeatureCounters& c, double& toi) {
  const Face& t = sf.topo->faces()[f];
  const VertexFaceQuery q{sv.v0[v], sf.v0[t[0]], sf.v0[t[1]], sf.v0[t[2]],
                          sv.v1[v], sf.v1[t[0]], sf.v1[t[1]], sf.v1[t[2]]};
  return k.ccd_hit(q, c.vf_tests, c.vf_np, toi);
}

bool ee_hit(const detail::FeatureContext& ca, int ea, const detail::FeatureContext& cb, int eb,
            detail::FeatureCounters& c, double& toi) {
  const Edge& x = ca.topo->edges()[ea];
  const Edge& y = cb.topo->edges()[eb];
  const EdgeEdgeQuery q{ca.v0[x[0]], ca.v0[x[1]], cb.v0[y[0]], cb.v0[y[1]],
                        ca.v1[x[0]], ca.v1[x[1]], cb.v1[y[0]], cb.v1[y[1]]};
  return ca.ccd_hit(q, c.ee_tests, c.ee_np, toi);
}

}  // namespace

clothcd::DetectResult brute_force_detect(const Topology& topo, const Positions& p0,
                                         const Positions& p1, const clothcd::DetectOptions& options,
                                         std::span<const std::uint8_t> active) {
  std::vector<Eigen::Vector3d> v0, v1;
  detail::to_points(p0, topo.num_vertices(), "positions at t0", v0);
  detail::to_points(p1, topo.num_vertices(), "positions at t1", v1);
  const auto links = detail::sorted_links(options.linked_vertices, topo.num_vertices());
  const detail::FeatureContext ctx = detail::ccd_context(topo, v0, v1, options, links);
  const bool restricted = !active.empty();
  std::vector<std::uint8_t> vact(topo.num_vertices(), 0), eact(topo.num_edges(), 0);
  for (int f = 0; f < topo.num_faces() && restricted; ++f) {
    if (active[f] == 0) continue;
    for (int v : topo.faces()[f])
      vact[v] = 1;
    for (int e : topo.face_edges(f))
      eact[e] = 1;
  }
  tbb::enumerable_thread_specific<Buffer> locals;
  const int nf = topo.num_faces(), ne = topo.num_edges();
  tbb::parallel_for(0, topo.num_vertices(), [&](int v) {
    if (topo.vertex_faces(v).empty()) return;
    const detail::Box bv = ctx.vertex_box(v);
    Buffer& out = locals.local();
    for (int f = 0; f < nf; ++f) {
      const Face& t = topo.faces()[f];
      if (v == t[0] || v == t[1] || v == t[2]) continue;
      if (restricted && vact[v] == 0 && active[f] == 0) continue;
      if (!detail::overlap(bv, ctx.face_box(f))) continue;
      ctx.kernel_vf(v, f, out.c, out.vf);
    }
  });
  std::vector<detail::Box> eboxes(ne);
  for (int e = 0; e < ne; ++e)
    eboxes[e] = ctx.edge_box(e);
  tbb::parallel_for(0, ne, [&](int ea) {
    Buffer& out = locals.local();
    const Edge& a = topo.edges()[ea];
    for (int eb = ea + 1; eb < ne; ++eb) {
      const Edge& b = topo.edges()[eb];
      if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) continue;
      if (restricted && eact[ea] == 0 && eact[eb] == 0) continue;
      if (!detail::overlap(eboxes[ea], eboxes[eb])) continue;
      ctx.kernel_ee(ea, eb, out.c, out.ee);
    }
  });
  clothcd::DetectResult res;
  for (const auto& l : locals) {
    l.c.add_to(res.stats);
    res.vf.insert(res.vf.end(), l.vf.begin(), l.vf.end());
    res.ee.insert(res.ee.end(), l.ee.begin(), l.ee.end());
  }
  std::sort(res.vf.begin(), res.vf.end(), detail::vf_less);
  std::sort(res.ee.begin(), res.ee.end(), detail::ee_less);
  res.stats.vf_collisions = res.vf.size();
  res.stats.ee_collisions = res.ee.size();
  return res;
}

PairDetectResult brute_force_detect_pair(const Topology& a, const Positions& a_t0,
                                         const Positions& a_t1, const Topology& b,
                                         const Positions& b_t0, const Positions& b_t1,
                                         const clothcd::DetectOptions& options) {
  std::vector<Eigen::Vector3d> a0, a1, b0, b1;
  detail::to_points(a_t0, a.num_vertices(), "mesh A at t0", a0);
  detail::to_points(a_t1, a.num_vertices(), "mesh A at t1", a1);
  detail::to_points(b_t0, b.num_vertices(), "mesh B at t0", b0);
  detail::to_points(b_t1, b.num_vertices(), "mesh B at t1", b1);
  const detail::FeatureContext ca = detail::ccd_context(a, a0, a1, options);
  const detail::FeatureContext cb = detail::ccd_context(b, b0, b1, options);
  tbb::enumerable_thread_specific<PairBuffer> locals;
  // Every vertex against every face of the other mesh, every edge against every edge.
  auto vertex_faces = [&](const detail::FeatureContext& sv, const detail::FeatureContext& sf,
                          auto member) {
    tbb::parallel_for(0, sv.topo->num_vertices(), [&](int v) {
      if (sv.topo->vertex_faces(v).empty()) return;
      PairBuffer& out = locals.local();
      const detail::Box bv = sv.vertex_box(v);
      for (int f = 0; f < sf.topo->num_faces(); ++f) {
        double toi = 1.0;
        if (detail::overlap(bv, sf.face_box(f)) && vf_hit(ca, sv, v, sf, f, out.c, toi)) {
          (out.*member).push_back({v, f, sf.topo->faces()[f], toi});
        }
      }
    });
  };
  vertex_faces(ca, cb, &PairBuffer::ab);
  vertex_faces(cb, ca, &PairBuffer::ba);
  tbb::parallel_for(0, a.num_edges(), [&](int ea) {
    PairBuffer& out = locals.local();
    const detail::Box xa = ca.edge_box(ea);
    for (int eb = 0; eb < b.num_edges(); ++eb) {
      double toi = 1.0;
      if (detail::overlap(xa, cb.edge_box(eb)) && ee_hit(ca, ea, cb, eb, out.c, toi)) {
        out.ee.push_back({ea, eb, a.edges()[ea], b.edges()[eb], toi});
      }
    }
  });
  return detail::collect_pair_results(locals);
}

}  // namespace clothcd::research
