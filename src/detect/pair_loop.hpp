#pragma once
// The narrow phase's one pair loop, which every query of both detectors runs (self and two-mesh
// CCD, self and two-mesh proximity): the traversal's triangle pairs in pieces, in parallel; each
// pair's face-box test; a whole-triangle filter a batch at a time; then the pair's feature pairs,
// which the caller's `features` tests (ownership, scope, filters and kernels), in list order.

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "detect/feature_boxes.hpp"
#include "detect/pair_list.hpp"

namespace clothcd::detail {

/// The whole-triangle filter a pass runs on the triangle pairs past the box test.
enum class TriangleFilter : std::uint8_t {
  None,    // every pair goes on to its features
  Swept,   // CCD: culls the pairs whose triangles stay farther apart than `distance` over the
           // step (FacesApartBatch)
  Static,  // proximity: culls the pairs whose triangles are farther apart than `distance` at
           // one set of positions (FaceBoundBatch)
};

/// One side of the triangle pairs: the mesh of their first faces, or of their second.
struct LoopSide {
  std::span<const Eigen::Vector3d> x0, x1;  // the step's positions (the same for a static query)
  const std::vector<Face>* faces = nullptr;
  // The faces' boxes, gathered per face (FeatureBoxes with face blocks) or plain; the box test
  // reads the blocks where there are any.
  std::span<const FaceBoxes> blocks;
  std::span<const Box> fboxes;
};

/// What a pass runs before the features, resolved once per call.
struct LoopPlan {
  TriangleFilter filter = TriangleFilter::None;
  double distance = 0;    // the filter's distance: the thickness, or the proximity distance h
  bool box_test = false;  // a pair's face boxes must overlap (widened leaves, kept pairs)
  // Optional: near[i] = whether pair i's triangles are at most near_distance apart at t1 (the
  // pairs a later proximity query may reuse), for every pair of the list.
  std::vector<std::uint8_t>* near = nullptr;
  double near_distance = 0;
};

/// Per-thread state the loop needs of the caller's buffer type.
struct LoopBuffers {
  FeatureCounters c;
  FacesApartBatch apart;
  FaceBoundBatch bound;
};

/// Runs `features(f, g, out)` on every pair of `pairs` that the plan keeps, `out` being the
/// calling thread's buffer (a type derived from LoopBuffers). `fetch(f, g)` is called for the
/// faces of the pair a few pairs ahead (it must be inlined: see SelfCore::fetch): the loop waits on
/// memory, a pair's records sitting at scattered places. Counts the pairs past the box test in
/// out.c.triangle_pairs and the Swept filter's culls in out.c.faces_apart.
template <class Local, class Fetch, class Features>
void pair_loop(const PairList& pairs, const LoopSide& a, const LoopSide& b, const LoopPlan& plan,
               tbb::enumerable_thread_specific<Local>& locals, Fetch&& fetch, Features&& features) {
  if (plan.near != nullptr) plan.near->assign(pairs.size(), 0);
  constexpr std::size_t kFar = 16, kPiece = 1024, kBatch = FacesApartBatch::kCapacity;
  static_assert(kBatch == FaceBoundBatch::kCapacity);
  const std::vector<Face>& fa = *a.faces;
  const std::vector<Face>& fb = *b.faces;
  const auto boxes_meet = [&](int f, int g) {
    if (!a.blocks.empty()) return a.blocks[f].face_overlaps(b.blocks[g]);
    return overlap(a.fboxes[f], b.fboxes[g]);
  };
  // Pairs [k0, k1) of a piece whose first pair is pair `first` of the list: the box test and
  // the queueing of the pairs past it, the filter on them at once, then their features. One
  // loop per filter, chosen once per call: no per-pair switch.
  const auto run = [&]<TriangleFilter kFilter>() {
    const auto chunk = [&](std::size_t first, std::span<const FacePair> piece, std::size_t k0,
                           std::size_t k1, Local& out) {
      FacesApartBatch& ap = out.apart;
      FaceBoundBatch& bd = out.bound;
      std::array<bool, kBatch> past;  // set for every pair of the chunk before it is read
      for (std::size_t k = k0; k < k1; ++k) {
        // In the loop body itself: to the compiler a call of a function that only prefetches
        // has no effect, and it deletes the call.
        if (k + kFar < piece.size()) fetch(piece[k + kFar].first, piece[k + kFar].second);
        const auto [f, g] = piece[k];
        const std::size_t s = k - k0;
        ap.slot[s] = bd.slot[s] = -1;
        past[s] = !plan.box_test || boxes_meet(f, g);
        if (!past[s]) {
          if (plan.near != nullptr) bd.slot[s] = bd.push(a.x1, fa[f], b.x1, fb[g]);
          continue;
        }
        if constexpr (kFilter == TriangleFilter::Swept) {
          ap.slot[s] = ap.push(a.x0, a.x1, fa[f], b.x0, b.x1, fb[g]);
        } else if constexpr (kFilter == TriangleFilter::Static) {
          bd.slot[s] = bd.push(a.x0, fa[f], b.x0, fb[g]);
        } else {
          if (plan.near != nullptr) bd.slot[s] = bd.push(a.x1, fa[f], b.x1, fb[g]);
        }
      }
      if (ap.pairs.size > 0) ap.run(plan.distance);
      if (bd.pairs.size > 0) bd.run();
      for (std::size_t k = k0; k < k1; ++k) {
        const std::size_t s = k - k0;
        const int sa = ap.slot[s], sb = bd.slot[s];
        std::uint8_t* near = plan.near != nullptr ? plan.near->data() + first + k : nullptr;
        if (!past[s]) {
          if (near != nullptr) *near = !(bd.bound[sb] > plan.near_distance);
          continue;
        }
        ++out.c.triangle_pairs;
        if constexpr (kFilter == TriangleFilter::Swept) {
          if (near != nullptr) *near = !(ap.bound_t1[sa] > plan.near_distance);
          if (ap.apart[sa]) {
            ++out.c.faces_apart;
            continue;
          }
        } else if constexpr (kFilter == TriangleFilter::Static) {
          if (bd.bound[sb] > plan.distance) continue;
        } else {
          if (near != nullptr) *near = !(bd.bound[sb] > plan.near_distance);
        }
        features(piece[k].first, piece[k].second, out);
      }
    };
    const std::vector<PairList::Piece> pieces = pairs.pieces(kPiece);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pieces.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        Local& out = locals.local();
                        for (std::size_t p = r.begin(); p != r.end(); ++p) {
                          const std::span<const FacePair> piece = pieces[p].pairs;
                          for (std::size_t k0 = 0; k0 < piece.size(); k0 += kBatch) {
                            chunk(pieces[p].first, piece, k0, std::min(piece.size(), k0 + kBatch),
                                  out);
                          }
                        }
                      });
  };
  switch (plan.filter) {
    case TriangleFilter::None:
      run.template operator()<TriangleFilter::None>();
      break;
    case TriangleFilter::Swept:
      run.template operator()<TriangleFilter::Swept>();
      break;
    case TriangleFilter::Static:
      run.template operator()<TriangleFilter::Static>();
      break;
  }
}

}  // namespace clothcd::detail
