// The candidates stage (clothcd/detect/candidates.hpp): the detector's ownership, orphans and
// linked-vertex rule with no boxes.

#include "clothcd/detect/candidates.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "narrow.hpp"
#include "orphans.hpp"

namespace clothcd {
namespace {

void sort_unique(std::vector<std::pair<int, int>>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

}  // namespace

struct Candidates::Impl {
  Topology topo;
  std::vector<std::pair<int, int>> links;
  detail::FeatureContext ctx;  // topology and links only: for the linked-vertex rule
  detail::Ownership owner;
  FeaturePairs orphans;

  Impl(const Topology& t, std::span<const std::pair<int, int>> linked)
      : topo(t),
        links(detail::sorted_links({linked.begin(), linked.end()}, topo.num_vertices())),
        owner(topo) {
    ctx.topo = &topo;
    ctx.links = links;
    detail::Orphans o = detail::find_orphans(topo);
    for (auto [v, f] : o.vf) {
      if (!ctx.vf_linked(v, f)) orphans.vf.emplace_back(v, f);
    }
    for (auto [a, b] : o.ee) {
      if (!ctx.ee_linked(a, b)) orphans.ee.emplace_back(a, b);
    }
  }
};

Candidates::Candidates(const Topology& topology,
                       std::span<const std::pair<int, int>> linked_vertices)
    : impl_(std::make_unique<Impl>(topology, linked_vertices)) {}
Candidates::~Candidates() = default;
Candidates::Candidates(Candidates&&) noexcept = default;
Candidates& Candidates::operator=(Candidates&&) noexcept = default;

void Candidates::append(int f, int g, FeaturePairs& out) const {
  const Impl& im = *impl_;
  const int nf = im.topo.num_faces();
  if (f < 0 || g < 0 || f >= nf || g >= nf) {
    throw InputError(fmt::format("triangle pair ({}, {}) is outside 0..{}", f, g, nf - 1));
  }
  if (detail::share_vertex(im.topo.faces()[f], im.topo.faces()[g])) return;
  detail::owned_feature_pairs(
      im.owner, detail::NoBoxes{}, f, g,
      [&](int v, int face, const Face&) {
        if (!im.ctx.vf_linked(v, face)) out.vf.emplace_back(v, face);
      },
      [&](int e1, int e2, const Edge&, const Edge&) {
        if (!im.ctx.ee_linked(e1, e2)) out.ee.emplace_back(e1, e2);
      });
}

const FeaturePairs& Candidates::orphans() const {
  return impl_->orphans;
}

FeaturePairs Candidates::operator()(std::span<const std::pair<int, int>> triangle_pairs) const {
  tbb::enumerable_thread_specific<FeaturePairs> locals;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangle_pairs.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      FeaturePairs& out = locals.local();
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        append(triangle_pairs[i].first, triangle_pairs[i].second, out);
                    });
  FeaturePairs all = impl_->orphans;
  for (const FeaturePairs& l : locals) {
    all.vf.insert(all.vf.end(), l.vf.begin(), l.vf.end());
    all.ee.insert(all.ee.end(), l.ee.begin(), l.ee.end());
  }
  sort_unique(all.vf);
  sort_unique(all.ee);
  return all;
}

}  // namespace clothcd
