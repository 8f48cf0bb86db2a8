// Brute-force references: every feature pair through the detector's own feature tests.

#include "clothcd/detect/oracle.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "narrow.hpp"
#include "positions.hpp"

namespace clothcd {
namespace {

struct Buffer {
  detail::FeatureCounters c;
  std::vector<VertexFaceCollision> vf;
  std::vector<EdgeEdgeCollision> ee;
};

}  // namespace

DetectResult brute_force_detect(const Topology& topo, const Positions& p0, const Positions& p1,
                                const DetectOptions& options,
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
  DetectResult res;
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

}  // namespace clothcd
