#pragma once
// A step's swept feature boxes, kept between calls (FeatureBoxes), and the box tests of a
// triangle pair's features, one at a time or a face block at a time (feature_overlaps).

#include "detect/feature_context.hpp"
#include "detect/pair_list.hpp"

namespace clothcd::detail {

/// Where FeatureBoxes keeps a step's edge and face boxes.
enum class BoxStore : std::uint8_t {
  Separate,  // one array per kind (vertices, edges, faces)
  Both,      // those arrays and the face blocks (FaceBoxes) that gather them per face
  // The face blocks only: a vertex's, an edge's and a face's boxes are read from a block
  // (FeatureContext::vertex_box, edge_box, face_box). The pair loop reads the blocks alone, and
  // the arrays would take another 72 bytes a face (290 MB on 4M triangles).
  Blocks,
};

/// The swept boxes of every vertex, edge and face for one step, kept between steps: `update`
/// recomputes only the boxes of features with a vertex whose positions (t0 or t1) changed since
/// the last update with the same margin. A box depends on nothing else, so the result is the same
/// as recomputing all of them; a restricted CCD pass, in which a few hundred vertices of the
/// cloth changed their motion, then pays for those alone (the full recomputation would be most
/// of such a pass).
class FeatureBoxes {
 public:
  /// `face_blocks`: also keep each face's boxes gathered as a FaceBoxes (FeatureContext::
  /// face_boxes), for the pair loop of owned_feature_pairs.
  explicit FeatureBoxes(bool face_blocks = false)
      : store_(face_blocks ? BoxStore::Both : BoxStore::Separate) {}
  explicit FeatureBoxes(BoxStore store) : store_(store) {}

  /// Brings the boxes up to date with ctx's positions and margin and points ctx at them (at no
  /// arrays with BoxStore::Blocks). ctx's positions must be `step`'s current ones:
  /// when the boxes were last updated at the previous call of `step` with the same margin, only
  /// the features of its changed vertices are redone.
  void update(FeatureContext& ctx, const StepPositions& step) {
    const Topology& topo = *ctx.topo;
    const int nv = topo.num_vertices();
    std::span<const std::uint8_t> moved = step.changed_since(call_);
    if (margin_ != ctx.margin) moved = {};  // every box changes: start over
    margin_ = ctx.margin;
    call_ = step.call();
    const bool arrays = store_ != BoxStore::Blocks, blocks = store_ != BoxStore::Separate;
    if (moved.empty()) {
      if (arrays) {
        vboxes_.resize(nv);
        eboxes_.resize(topo.num_edges());
        fboxes_.resize(topo.num_faces());
      }
      if (blocks) blocks_.resize(topo.num_faces());
    }
    const auto redo = [&](auto&& ids) {  // a vertex of the feature moved (or all did)
      if (moved.empty()) return true;
      for (int v : ids) {
        if (moved[v]) return true;
      }
      return false;
    };
    // An edge's or face's box is the union of its vertices' boxes bit for bit: swept_feature_box's
    // rounding (minus the margin, next_down, to float downwards) is monotone, so the rounded
    // minimum of the points is the minimum of their rounded values (likewise upwards).
    if (arrays) {
      for_each(nv, [&](int i) {
        if (redo(std::array<int, 1>{i})) vboxes_[i] = ctx.compute_vertex_box(i);
      });
      for_each(topo.num_edges(), [&](int e) {
        if (redo(topo.edges()[e])) eboxes_[e] = merged(vboxes_, topo.edges()[e]);
      });
      for_each(topo.num_faces(), [&](int f) {
        if (redo(topo.faces()[f])) fboxes_[f] = merged(vboxes_, topo.faces()[f]);
      });
    }
    if (blocks) {
      // A face's block holds its own, its edges' and its corners' boxes, redone exactly when one
      // of those is (a vertex of the face moved). Without the arrays, the corners' boxes come
      // from the same function and are merged in the same order: the same bits. When every block
      // is redone, from a transient array of the vertices' boxes, each computed once (freed
      // before the call's traversal and results).
      std::vector<Box, MappedAllocator<Box>> vertex;  // its memory leaves with it
      if (!arrays && moved.empty()) {
        vertex.resize(nv);
        for_each(nv, [&](int i) { vertex[i] = ctx.compute_vertex_box(i); });
      }
      const auto vertex_box = [&](int v) {
        return vertex.empty() ? ctx.compute_vertex_box(v) : vertex[v];
      };
      for_each(topo.num_faces(), [&](int f) {
        const Face& t = topo.faces()[f];
        if (!redo(t)) return;
        FaceBoxes& b = blocks_[f];
        const auto& edges = topo.face_edges(f);
        if (arrays) {
          for (int k = 0; k < 3; ++k) {
            b.set(FaceBoxes::kEdges + k, eboxes_[edges[k]]);
            b.set(FaceBoxes::kCorners + k, vboxes_[t[k]]);
          }
          b.set(FaceBoxes::kFace, fboxes_[f]);
          b.set(7, fboxes_[f]);
          return;
        }
        const std::array<Box, 3> corner = {vertex_box(t[0]), vertex_box(t[1]), vertex_box(t[2])};
        for (int k = 0; k < 3; ++k) {
          // Edge k joins corners k and k + 1, merged in the order Topology::edges() lists them.
          const int k1 = k == 2 ? 0 : k + 1;
          const bool ordered = topo.edges()[edges[k]][0] == t[k];
          const std::array<int, 2> ends = ordered ? std::array{k, k1} : std::array{k1, k};
          b.set(FaceBoxes::kEdges + k, merged(corner, ends));
          b.set(FaceBoxes::kCorners + k, corner[k]);
        }
        const Box face = merged(corner, std::array{0, 1, 2});
        b.set(FaceBoxes::kFace, face);
        b.set(7, face);
      });
      ctx.face_boxes = blocks_;
    }
    ctx.vboxes = arrays ? std::span<const Box>(vboxes_) : std::span<const Box>();
    ctx.eboxes = arrays ? std::span<const Box>(eboxes_) : std::span<const Box>();
    ctx.fboxes = arrays ? std::span<const Box>(fboxes_) : std::span<const Box>();
  }

 private:
  // The union of boxes[ids[0]], boxes[ids[1]], ... in that order.
  template <class Boxes, class Ids>
  [[nodiscard]] static Box merged(const Boxes& boxes, const Ids& ids) {
    Box b = boxes[ids[0]];
    for (std::size_t k = 1; k < ids.size(); ++k) {
      const Box& o = boxes[ids[k]];
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

  BoxStore store_ = BoxStore::Separate;
  std::vector<Box> vboxes_, eboxes_, fboxes_;
  std::vector<FaceBoxes> blocks_;
  std::uint64_t call_ = 0;  // the StepPositions call the boxes were computed at (0: none)
  double margin_ = -1.0;
};

/// A hint to fetch the cache line holding `p` (no effect on results). Inlined always: a call of
/// a function that only prefetches counts as free of side effects, and the compiler drops it.
[[gnu::always_inline]] inline void prefetch(const void* p) {
#if defined(__GNUC__)
  __builtin_prefetch(p);
#else
  (void)p;
#endif
}

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

}  // namespace clothcd::detail
