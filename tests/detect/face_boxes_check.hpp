#pragma once
// The pair loop's per-face box blocks (detail::FaceBoxes, StepFaceBoxes) against the separate
// boxes (StepBoxes) for one step: the same blocks as the boxes they gather, the same overlaps and
// the same feature pairs, in the same order, from owned_feature_pairs. Shared by the face box
// tests.

#include <gtest/gtest.h>

#include <cstring>
#include <tuple>
#include <vector>

#include "detect/narrow.hpp"
#include "detect/step_positions.hpp"

namespace clothcd::face_boxes_check {

/// The context of `step`'s current positions with the boxes' margin only (no CCD settings).
inline detail::FeatureContext step_context(const Topology& topo, const detail::StepPositions& step,
                                           double margin) {
  detail::FeatureContext ctx;
  ctx.topo = &topo;
  ctx.v0 = step.x0();
  ctx.v1 = step.x1();
  ctx.margin = margin;
  return ctx;
}

// One yielded feature pair: (0, vertex, face) or (1, edge, edge).
using Yield = std::tuple<int, int, int>;

template <class Boxes>
std::vector<Yield> yielded(const detail::Ownership& owner, const Boxes& boxes, int f, int g) {
  std::vector<Yield> out;
  detail::owned_feature_pairs(
      owner, boxes, f, g, [&](int v, int face, const Face&) { out.emplace_back(0, v, face); },
      [&](int e1, int e2, const Edge&, const Edge&) { out.emplace_back(1, e1, e2); });
  return out;
}

inline bool same(const detail::Box& a, const detail::Box& b) {
  return std::memcmp(&a, &b, sizeof(detail::Box)) == 0;
}

/// Every block of ctx holds copies of its face's, edges' and corners' boxes.
inline void expect_blocks(const detail::FeatureContext& ctx) {
  const Topology& t = *ctx.topo;
  ASSERT_EQ(ctx.face_boxes.size(), static_cast<std::size_t>(t.num_faces()));
  for (int f = 0; f < t.num_faces(); ++f) {
    const detail::FaceBoxes& b = ctx.face_boxes[f];
    ASSERT_TRUE(same(b.face(), ctx.fboxes[f])) << "face " << f;
    ASSERT_TRUE(same(b.get(7), ctx.fboxes[f])) << "face " << f;
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(same(b.get(detail::FaceBoxes::kEdges + k), ctx.eboxes[t.face_edges(f)[k]]))
          << "face " << f << " edge " << k;
      ASSERT_TRUE(same(b.get(detail::FaceBoxes::kCorners + k), ctx.vboxes[t.faces()[f][k]]))
          << "face " << f << " corner " << k;
    }
  }
}

/// For the pair (f, g), sharing no vertex: the same overlaps from the blocks (vector and lane by
/// lane) as from the separate boxes, the same search masks from both forms, and the same
/// feature pairs in the same order. Returns the
/// number of feature pairs.
inline std::size_t check_pair(const detail::Ownership& owner, const detail::FeatureContext& ctx,
                              int f, int g) {
  const detail::StepBoxes separate{ctx};
  const detail::StepFaceBoxes blocks{ctx};
  const auto& rf = owner.record(f);
  const auto& rg = owner.record(g);
  const detail::FeatureOverlaps want = separate.overlaps(rf, rg, f, g);
  EXPECT_EQ(blocks.overlaps(rf, rg, f, g), want) << "faces " << f << ", " << g;
  EXPECT_EQ(detail::feature_overlaps_scalar(ctx.face_boxes[f], ctx.face_boxes[g]), want)
      << "faces " << f << ", " << g;
  EXPECT_EQ(detail::search_masks(rf, rg), detail::search_masks_scalar(rf, rg))
      << "faces " << f << ", " << g;
  const auto pairs = yielded(owner, separate, f, g);
  EXPECT_EQ(yielded(owner, blocks, f, g), pairs) << "faces " << f << ", " << g;
  return pairs.size();
}

}  // namespace clothcd::face_boxes_check
