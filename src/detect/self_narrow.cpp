// The self detector's narrow phase: the pair loop over the traversal's triangle pairs (feature
// boxes, ownership, the batched filters and the kernels) and the orphan pairs, then the results
// gathered and sorted.

#include <tbb/parallel_for.h>

#include <algorithm>

#include "detect/self_core.hpp"

namespace clothcd::detail {

void SelfCore::narrow(const detail::FeatureContext& ctx, const detail::PairList& pairs,
                      DetectResult& res, std::vector<std::uint8_t>* near) {
  NarrowLocals locals;
  narrow_pairs(ctx, pairs, locals, near);
  narrow_orphans(ctx, locals);
  res.stats.triangle_pairs = 0;
  gather(locals, res);
  finish(res);
}

void SelfCore::narrow_pairs(const detail::FeatureContext& ctx, const detail::PairList& pairs,
                            NarrowLocals& locals, std::vector<std::uint8_t>* near) const {
  const bool wide = box_reach() > opt.thickness;
  if (near != nullptr) near->assign(pairs.size(), 0);
  const auto& faces = topo.faces();
  auto kvf = [&](int v, int f, const Face& t, NarrowBuffer& out) {
    ctx.queue_vf(v, f, t, out.batch, out.c, out.vf);
  };
  auto kee = [&](int a, int b, const Edge& ea, const Edge& eb, NarrowBuffer& out) {
    ctx.queue_ee(a, b, ea, eb, out.batch, out.c, out.ee);
  };
  // The pair loop waits on memory: a triangle pair's records and box blocks sit at scattered
  // places. Fetch them kFar pairs ahead (a record is one cache line, a block three), within
  // a piece of the list.
  constexpr std::size_t kFar = 16, kPiece = 1024;
  const auto fetch_face = [&](int f) {
    detail::prefetch(&owner.record(f));
    const auto* block = reinterpret_cast<const char*>(&ctx.face_boxes[f]);
    for (int line = 0; line < 3; ++line)
      detail::prefetch(block + 64 * line);
  };
  // Without the whole-triangle bound (faces_apart_filter), pair i of the list, faces f and g.
  const auto one = [&](std::size_t i, int f, int g, NarrowBuffer& out) {
    if (near != nullptr) {
      (*near)[i] = !(ccd_detail::triangle_triangle_bound(ccd_detail::corners(v1, faces[f]),
                                                         ccd_detail::corners(v1, faces[g])) >
                     opt.reuse_distance);
    }
    // Widened leaf boxes: no feature pair of faces whose own boxes miss.
    if (wide && !ctx.face_boxes[f].face_overlaps(ctx.face_boxes[g])) return;
    ++out.c.triangle_pairs;
    triangle_pair(ctx, f, g, out, kvf, kee);
  };
  // With it, pairs [k0, k1) of a piece: the box test and the queueing of the
  // pairs past it, the whole-triangle filter on them at once, then their feature pairs, in
  // list order.
  const auto batch = [&](std::size_t first, std::span<const detail::FacePair> piece, std::size_t k0,
                         std::size_t k1, NarrowBuffer& out) {
    detail::FacesApartBatch& fb = out.faces;
    detail::FaceBoundBatch& nb = out.near;
    for (std::size_t k = k0; k < k1; ++k) {
      if (k + kFar < piece.size()) {
        fetch_face(piece[k + kFar].first);
        fetch_face(piece[k + kFar].second);
      }
      const auto [f, g] = piece[k];
      fb.slot[k - k0] = nb.slot[k - k0] = -1;
      if (wide && !ctx.face_boxes[f].face_overlaps(ctx.face_boxes[g])) {
        if (near != nullptr) nb.slot[k - k0] = nb.push(ctx.v1, faces[f], ctx.v1, faces[g]);
        continue;
      }
      fb.slot[k - k0] = fb.push(ctx.v0, ctx.v1, faces[f], ctx.v0, ctx.v1, faces[g]);
    }
    if (nb.pairs.size > 0) {
      nb.run();
      for (std::size_t k = k0; k < k1; ++k) {
        const int s = nb.slot[k - k0];
        if (s >= 0) (*near)[first + k] = !(nb.bound[s] > opt.reuse_distance);
      }
    }
    fb.run(ctx.ccd.thickness);
    for (std::size_t k = k0; k < k1; ++k) {
      const int s = fb.slot[k - k0];
      if (s < 0) continue;
      ++out.c.triangle_pairs;
      if (near != nullptr) (*near)[first + k] = !(fb.bound_t1[s] > opt.reuse_distance);
      if (fb.apart[s]) {
        ++out.c.faces_apart;
        continue;
      }
      triangle_pair(ctx, piece[k].first, piece[k].second, out, kvf, kee);
    }
  };
  const bool batched = ctx.faces_apart_filter();
  constexpr std::size_t kBatch = detail::FacesApartBatch::kCapacity;
  const std::vector<detail::PairList::Piece> pieces = pairs.pieces(kPiece);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pieces.size(), 1),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      NarrowBuffer& out = locals.local();
                      for (std::size_t p = r.begin(); p != r.end(); ++p) {
                        const std::span<const detail::FacePair> piece = pieces[p].pairs;
                        if (batched) {
                          for (std::size_t k0 = 0; k0 < piece.size(); k0 += kBatch) {
                            batch(pieces[p].first, piece, k0, std::min(piece.size(), k0 + kBatch),
                                  out);
                          }
                          continue;
                        }
                        for (std::size_t k = 0; k < piece.size(); ++k) {
                          if (k + kFar < piece.size()) {
                            fetch_face(piece[k + kFar].first);
                            fetch_face(piece[k + kFar].second);
                          }
                          one(pieces[p].first + k, piece[k].first, piece[k].second, out);
                        }
                      }
                    });
  for (auto& l : locals)  // at most one partial batch of each kind per thread
    ctx.flush(l.batch, l.c, l.vf, l.ee);
}

void SelfCore::narrow_orphans(const detail::FeatureContext& ctx, NarrowLocals& locals) const {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, orphans.vf.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      NarrowBuffer& out = locals.local();
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const auto [v, f] = orphans.vf[i];
                        if (!vf_in_scope(v, f)) continue;
                        if (!detail::overlap(ctx.vertex_box(v), ctx.face_box(f))) continue;
                        ctx.kernel_vf(v, f, out.c, out.vf);
                      }
                    });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, orphans.ee.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      NarrowBuffer& out = locals.local();
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const auto [ea, eb] = orphans.ee[i];
                        if (!ee_in_scope(ea, eb)) continue;
                        if (!detail::overlap(ctx.edge_box(ea), ctx.edge_box(eb))) continue;
                        ctx.kernel_ee(ea, eb, out.c, out.ee);
                      }
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
  std::sort(res.vf.begin(), res.vf.end(), detail::vf_less);
  std::sort(res.ee.begin(), res.ee.end(), detail::ee_less);
  st.vf_collisions = res.vf.size();
  st.ee_collisions = res.ee.size();
}

}  // namespace clothcd::detail
