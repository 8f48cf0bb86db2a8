// The self detector's proximity query: the box traversal at distance h (or the pairs kept by
// the last detect() for the vertices still where it left them), then the triangles' bound and
// the distance of every owned feature pair within reach.

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "ccd/batch.hpp"
#include "detect/self_core.hpp"

namespace clothcd::detail {

ProximityResult SelfCore::proximity(detail::PointsIn p, double h) {
  if (!(h >= 0) || !std::isfinite(h)) {
    throw InputError(fmt::format("proximity distance must be finite and >= 0, got {}", h));
  }
  step.update_static(p, topo.num_vertices(), "positions");
  update_links();
  RefitOptions ro;
  ro.thickness = h;
  ro.cones = false;  // cones carry no distance information (docs/algorithms.md 1.1)
  bvh.refit(v0, ro);
  bvh_call = 0;
  detail::FeatureContext ctx = detail::proximity_context(topo, v0, h, links);
  boxes.update(ctx, step);
  struct Buffer {
    std::vector<ProximityResult::VertexFace> vf;
    std::vector<ProximityResult::EdgeEdge> ee;
    detail::FaceBoundBatch bounds;  // a piece's triangle pairs past the box test
  };
  tbb::enumerable_thread_specific<Buffer> locals;
  // Linked pairs are left out as detect() leaves them out (DetectOptions::linked_vertices).
  auto kvf = [&](int v, int f, const Face& t, Buffer& out) {
    if (!ctx.links.empty() && ctx.vf_linked(v, f)) return;
    const double d = ccd_detail::point_triangle_within(v0[v], v0[t[0]], v0[t[1]], v0[t[2]], h);
    if (d <= h) out.vf.push_back({v, f, d});
  };
  auto kee = [&](int a, int b, const Edge& ea, const Edge& eb, Buffer& out) {
    if (!ctx.links.empty() && ctx.ee_linked(a, b)) return;
    const double d = ccd_detail::edge_edge_within(v0[ea[0]], v0[ea[1]], v0[eb[0]], v0[eb[1]], h);
    if (d <= h) out.ee.push_back({a, b, d});
  };
  // A piece at a time: the box test, the whole triangles' bound of the pairs past it at once
  // (no feature pair is closer), then the feature pairs of those within h, in list order.
  auto test_pairs = [&](const detail::PairList& pairs) {
    const std::vector<detail::PairList::Piece> pieces =
        pairs.pieces(detail::FaceBoundBatch::kCapacity);
    const auto& faces = topo.faces();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pieces.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        Buffer& out = locals.local();
                        detail::FaceBoundBatch& nb = out.bounds;
                        for (std::size_t p = r.begin(); p != r.end(); ++p) {
                          const std::span<const detail::FacePair> piece = pieces[p].pairs;
                          for (std::size_t k = 0; k < piece.size(); ++k) {
                            const auto [f, g] = piece[k];
                            nb.slot[k] = detail::overlap(ctx.fboxes[f], ctx.fboxes[g])
                                             ? nb.push(v0, faces[f], v0, faces[g])
                                             : -1;
                          }
                          nb.run();
                          for (std::size_t k = 0; k < piece.size(); ++k) {
                            const int s = nb.slot[k];
                            if (s < 0 || nb.bound[s] > h) continue;
                            triangle_pair(ctx, piece[k].first, piece[k].second, out, kvf, kee);
                          }
                        }
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
      ~Unrestrict() { im.restricted = im.outside = false; }
    } unrestrict{*this};
    outside = true;
    test_pairs(detail::PairList(reuse.pairs));
    reused = reuse.pairs.size();
    outside = false;
    test_pairs(traverse(Rule::None, st, pair_locals));
  } else {
    test_pairs(traverse(Rule::None, st, pair_locals));
  }
  Buffer& out = locals.local();
  for (const auto& [v, f] : orphans.vf) {
    if (vf_in_scope(v, f) && detail::overlap(ctx.vertex_box(v), ctx.face_box(f))) {
      kvf(v, f, topo.faces()[f], out);
    }
  }
  for (const auto& [a, b] : orphans.ee) {
    if (ee_in_scope(a, b) && detail::overlap(ctx.edge_box(a), ctx.edge_box(b))) {
      kee(a, b, topo.edges()[a], topo.edges()[b], out);
    }
  }
  ProximityResult res;
  res.reused_pairs = reused;
  for (const auto& l : locals) {
    res.vf.insert(res.vf.end(), l.vf.begin(), l.vf.end());
    res.ee.insert(res.ee.end(), l.ee.begin(), l.ee.end());
  }
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
  set_active_vertices(moved);
  return true;
}

}  // namespace clothcd::detail
