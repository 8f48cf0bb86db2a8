// The self detector's proximity query: the box traversal at distance h (or the pairs kept by
// the last detect() for the vertices still where it left them), then the pair loop
// (pair_loop.hpp) with the triangles' bound and the distance of every owned feature pair within
// reach.

#include <algorithm>
#include <cmath>

#include "ccd/batch.hpp"
#include "detect/self_core.hpp"

namespace clothcd::detail {
namespace {
// A large query finds millions of pairs: in blocks, which neither copy them as they grow nor
// hold twice their memory at a doubling, and which are freed as they are gathered.
struct ProximityBuffer : LoopBuffers {
  MappedBlocks<ProximityResult::VertexFace> vf;
  MappedBlocks<ProximityResult::EdgeEdge> ee;
};
}  // namespace

ProximityResult SelfCore::proximity(PointsIn p, double h) {
  if (!(h >= 0) || !std::isfinite(h)) {
    throw InputError(fmt::format("proximity distance must be finite and >= 0, got {}", h));
  }
  step.update_static(p, topo.num_vertices(), "positions");
  update_links();
  refit_static(h);
  FeatureContext ctx = proximity_context(topo, v0, h, links);
  boxes.update(ctx, step);
  tbb::enumerable_thread_specific<ProximityBuffer> locals;
  // Linked pairs are left out as detect() leaves them out (DetectOptions::linked_vertices).
  auto kvf = [&](int v, int f, const Face& t, ProximityBuffer& out) {
    if (!ctx.links.empty() && ctx.vf_linked(v, f)) return;
    const double d = ccd_detail::point_triangle_within(v0[v], v0[t[0]], v0[t[1]], v0[t[2]], h);
    if (d <= h) out.vf.push_back({v, f, d});
  };
  auto kee = [&](int a, int b, const Edge& ea, const Edge& eb, ProximityBuffer& out) {
    if (!ctx.links.empty() && ctx.ee_linked(a, b)) return;
    const double d = ccd_detail::edge_edge_within(v0[ea[0]], v0[ea[1]], v0[eb[0]], v0[eb[1]], h);
    if (d <= h) out.ee.push_back({a, b, d});
  };
  // The box test, the whole triangles' bound (no feature pair is closer), then the feature
  // pairs of the triangle pairs within h.
  LoopPlan plan;
  plan.filter = TriangleFilter::Static;
  plan.distance = h;
  plan.box_test = true;
  const LoopSide side = loop_side(ctx);
  const auto test_pairs = [&](const PairList& pairs, Scope scope) {
    pair_loop(pairs, side, side, plan, locals, fetch(ctx), [&](int f, int g, ProximityBuffer& out) {
      triangle_pair(ctx, scope, f, g, out, kvf, kee);
    });
  };
  DetectStats st;
  std::size_t reused = 0;
  if (reusable(h)) {
    // The kept pairs hold every pair of features on vertices still at their t1 positions (the
    // widened boxes held these positions and more); a traversal restricted to the moved
    // vertices finds the rest. The two scopes split the feature pairs exactly.
    struct Unrestrict {
      SelfCore& im;
      ~Unrestrict() { im.clear_active(); }
    } unrestrict{*this};
    test_pairs(PairList(reuse.pairs), Scope::Inactive);
    reused = reuse.pairs.size();
    traverse_each(Rule::None, Scope::Active, st, pair_locals, false,
                  [&](const PairList& pairs) { test_pairs(pairs, Scope::Active); });
  } else {
    traverse_each(Rule::None, scope(), st, pair_locals, false,
                  [&](const PairList& pairs) { test_pairs(pairs, scope()); });
  }
  orphan_pairs(ctx, scope(), locals, kvf, kee);
  ProximityResult res;
  res.reused_pairs = reused;
  drain_into(locals, &ProximityBuffer::vf, res.vf);
  drain_into(locals, &ProximityBuffer::ee, res.ee);
  std::sort(res.vf.begin(), res.vf.end(), [](const auto& a, const auto& b) {
    return std::pair(a.vertex, a.face) < std::pair(b.vertex, b.face);
  });
  std::sort(res.ee.begin(), res.ee.end(), [](const auto& a, const auto& b) {
    return std::pair(a.edge_a, a.edge_b) < std::pair(b.edge_a, b.edge_b);
  });
  return res;
}

bool SelfCore::reusable(double h) {
  if (!reuse.valid || restricted || h > opt.reuse_distance) return false;
  const int nv = topo.num_vertices();
  std::vector<int> moved;
  for (int i = 0; i < nv; ++i) {
    if (v0[i] != reuse.x1[i]) moved.push_back(i);
  }
  if (4 * moved.size() > static_cast<std::size_t>(nv)) return false;
  set_active_vertices(moved, "");
  return true;
}

}  // namespace clothcd::detail
