#pragma once
// R-triangle ownership (docs/algorithms.md 6.3): which triangle pair tests a feature pair, from
// per-face records (Ownership), and the pair loop's step over one triangle pair's owned feature
// pairs past their box tests (owned_feature_pairs).

#include "detect/feature_boxes.hpp"

namespace clothcd::detail {

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
    // Every face's record depends on the topology alone: filled in parallel.
    const auto for_each = [](int n, auto&& fn) {
      tbb::parallel_for(tbb::blocked_range<int>(0, n, 4096), [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i)
          fn(i);
      });
    };
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
    // Read from the topology: few feature pairs need the search (the records settle the
    // others), and per-edge copies of the faces would take 8 to 36 bytes an edge.
    const auto& faces = topo_->faces();
    for (int fa : topo_->edge_faces(e1)) {
      for (int fb : topo_->edge_faces(e2)) {
        if (fa == x && fb == y) return true;
        if (!share_vertex(faces[fa], faces[fb])) return false;
      }
    }
    return false;
  }

 private:
  const Topology* topo_ = nullptr;
  std::vector<FaceRecord> records_;
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
