// The self detector's CCD narrow phase: the pair loop (pair_loop.hpp) over the traversal's
// triangle pairs, their owned feature pairs through the batched filters and kernels, the orphan
// pairs, then the results gathered and sorted.

#include <algorithm>

#include "detect/self_core.hpp"

namespace clothcd::detail {

void SelfCore::narrow(const FeatureContext& ctx, const PairList& pairs, Scope scope,
                      DetectResult& res, std::vector<std::uint8_t>* near) {
  NarrowLocals locals;
  narrow_pairs(ctx, pairs, scope, locals, near);
  narrow_orphans(ctx, scope, locals);
  res.stats.triangle_pairs = 0;
  gather(locals, res);
  finish(res);
}

void SelfCore::narrow_pairs(const FeatureContext& ctx, const PairList& pairs, Scope scope,
                            NarrowLocals& locals, std::vector<std::uint8_t>* near) const {
  LoopPlan plan;
  plan.filter = ctx.plan.faces_apart ? TriangleFilter::Swept : TriangleFilter::None;
  plan.distance = ctx.ccd.thickness;
  // Widened leaf boxes: no feature pair of faces whose own boxes miss.
  plan.box_test = box_reach() > opt.thickness;
  plan.near = near;
  plan.near_distance = opt.reuse_distance;
  auto kvf = [&](int v, int f, const Face& t, NarrowBuffer& out) {
    ctx.queue_vf(v, f, t, out.batch, out.c, out.vf);
  };
  auto kee = [&](int a, int b, const Edge& ea, const Edge& eb, NarrowBuffer& out) {
    ctx.queue_ee(a, b, ea, eb, out.batch, out.c, out.ee);
  };
  const LoopSide side = loop_side(ctx);
  pair_loop(pairs, side, side, plan, locals, fetch(ctx), [&](int f, int g, NarrowBuffer& out) {
    triangle_pair(ctx, scope, f, g, out, kvf, kee);
  });
  for (auto& l : locals)  // at most one partial batch of each kind per thread
    ctx.flush(l.batch, l.c, l.vf, l.ee);
}

void SelfCore::narrow_orphans(const FeatureContext& ctx, Scope scope, NarrowLocals& locals) const {
  orphan_pairs(
      ctx, scope, locals,
      [&](int v, int f, const Face&, NarrowBuffer& out) { ctx.kernel_vf(v, f, out.c, out.vf); },
      [&](int a, int b, const Edge&, const Edge&, NarrowBuffer& out) {
        ctx.kernel_ee(a, b, out.c, out.ee);
      });
}

void SelfCore::gather(const NarrowLocals& locals, DetectResult& res) {
  DetectStats& st = res.stats;
  for (const auto& l : locals) {
    l.c.add_to(st);
    st.triangle_pairs += l.c.triangle_pairs;
    res.vf.insert(res.vf.end(), l.vf.begin(), l.vf.end());
    res.ee.insert(res.ee.end(), l.ee.begin(), l.ee.end());
  }
}

void SelfCore::finish(DetectResult& res) const {
  DetectStats& st = res.stats;
  st.vf_orphans = orphans.vf.size();
  st.ee_orphans = orphans.ee.size();
  std::sort(res.vf.begin(), res.vf.end(), vf_less);
  std::sort(res.ee.begin(), res.ee.end(), ee_less);
  st.vf_collisions = res.vf.size();
  st.ee_collisions = res.ee.size();
}

}  // namespace clothcd::detail
