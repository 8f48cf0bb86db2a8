#pragma once
// The narrow phase's feature pairs in blocks: VF and EE candidates (boxes overlapping, owned by
// the triangle pair, in scope) are collected per thread, their positions gathered into
// structure-of-arrays blocks, and the NP filter runs on whole SIMD vectors (ccd/np_batch.hpp);
// only the pairs it does not cull (about a third on cloth_ball) take the scalar kernel. The
// vector filter's verdicts are the scalar filter's bit for bit, so results and counters are
// those of one kernel call per pair (FeatureContext::kernel_vf / kernel_ee).

#include <array>
#include <utility>
#include <vector>

#include "ccd/np_batch.hpp"
#include "narrow.hpp"

namespace clothcd::detail {

class FeatureBatch {
 public:
  /// Whether ctx's kernel starts with the unscaled NP filter and counts its culls (zero
  /// thickness, fast path and NP filter on): the only setting the batch reproduces. Otherwise use
  /// kernel_vf / kernel_ee directly.
  [[nodiscard]] static bool applies(const FeatureContext& ctx) {
    return ctx.np_filter && ctx.ccd.thickness == 0 && ctx.ccd.fast_path;
  }

  void add_vf(const FeatureContext& ctx, int v, int f, FeatureCounters& c,
              std::vector<VertexFaceCollision>& out) {
    if (!ctx.links.empty()) {  // linked vertices are rare: test for them only when there are any
      const Face& t = ctx.topo->faces()[f];
      if (ctx.grouped(v, t[0]) || ctx.grouped(v, t[1]) || ctx.grouped(v, t[2])) return;
    }
    vf_[nvf_++] = {v, f};
    if (nvf_ == kSize) flush_vf(ctx, c, out);
  }

  /// Edges ea < eb.
  void add_ee(const FeatureContext& ctx, int ea, int eb, FeatureCounters& c,
              std::vector<EdgeEdgeCollision>& out) {
    if (!ctx.links.empty()) {
      const Edge& a = ctx.topo->edges()[ea];
      const Edge& b = ctx.topo->edges()[eb];
      if (ctx.grouped(a[0], b[0]) || ctx.grouped(a[0], b[1]) || ctx.grouped(a[1], b[0]) ||
          ctx.grouped(a[1], b[1])) {
        return;
      }
    }
    ee_[nee_++] = {ea, eb};
    if (nee_ == kSize) flush_ee(ctx, c, out);
  }

  /// Tests the pairs still collected.
  void flush(const FeatureContext& ctx, FeatureCounters& c, std::vector<VertexFaceCollision>& vf,
             std::vector<EdgeEdgeCollision>& ee) {
    if (nvf_ > 0) flush_vf(ctx, c, vf);
    if (nee_ > 0) flush_ee(ctx, c, ee);
  }

 private:
  static constexpr int kSize = ccd_detail::NpBlock::kSize;

  void gather(const FeatureContext& ctx, int lane, const std::array<int, 4>& pts) {
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d& p0 = ctx.v0[pts[k]];
      const Eigen::Vector3d& p1 = ctx.v1[pts[k]];
      for (int c = 0; c < 3; ++c) {
        block_.x[k][c][lane] = p0[c];
        block_.x[k + 4][c][lane] = p1[c];
      }
    }
  }

  void flush_vf(const FeatureContext& ctx, FeatureCounters& c,
                std::vector<VertexFaceCollision>& out) {
    const auto& faces = ctx.topo->faces();
    for (int i = 0; i < nvf_; ++i) {
      const auto [v, f] = vf_[i];
      const Face& t = faces[f];
      gather(ctx, i, {v, t[0], t[1], t[2]});
    }
    block_.n = nvf_;
    ccd_detail::np_filter_block(ccd_detail::Kind::vertex_face, block_, culled_.data());
    for (int i = 0; i < nvf_; ++i) {
      if (culled_[i] != 0) {
        ++c.vf_tests;
        ++c.vf_np;
      } else {
        ctx.kernel_vf_unfiltered(vf_[i].first, vf_[i].second, c, out);
      }
    }
    nvf_ = 0;
  }

  void flush_ee(const FeatureContext& ctx, FeatureCounters& c,
                std::vector<EdgeEdgeCollision>& out) {
    const auto& edges = ctx.topo->edges();
    for (int i = 0; i < nee_; ++i) {
      const Edge& a = edges[ee_[i].first];
      const Edge& b = edges[ee_[i].second];
      gather(ctx, i, {a[0], a[1], b[0], b[1]});
    }
    block_.n = nee_;
    ccd_detail::np_filter_block(ccd_detail::Kind::edge_edge, block_, culled_.data());
    for (int i = 0; i < nee_; ++i) {
      if (culled_[i] != 0) {
        ++c.ee_tests;
        ++c.ee_np;
      } else {
        ctx.kernel_ee_unfiltered(ee_[i].first, ee_[i].second, c, out);
      }
    }
    nee_ = 0;
  }

  ccd_detail::NpBlock block_;
  std::array<std::uint8_t, kSize> culled_{};
  std::array<std::pair<int, int>, kSize> vf_{}, ee_{};
  int nvf_ = 0, nee_ = 0;
};

}  // namespace clothcd::detail
