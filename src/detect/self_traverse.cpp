// The self detector's culled traversal: which internal nodes the culling rule skips (cones,
// contours and, with a contact distance, corner clearances), and the walk from the root or from
// the last call's front that hands the overlapping non-adjacent leaf pairs to the narrow phase.

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "detect/clearance.hpp"
#include "detect/contour.hpp"
#include "detect/self_core.hpp"

namespace clothcd::detail {
namespace {
// Cones are compared against pi/2 with a small margin for the rounding of the merges.
constexpr double kConeMargin = 1e-9;
}  // namespace

double SelfCore::cull_reach(const BvhNode& n) const {
  double extent = 0, scale = 0;
  for (int k = 0; k < 3; ++k) {
    extent = std::max(extent, n.hi[k] - n.lo[k]);
    scale = std::max({scale, std::abs(n.lo[k]), std::abs(n.hi[k])});
  }
  const double kernel = std::sqrt(3.0) * (opt.thickness + CcdOptions{}.tolerance * extent);
  return kernel * (1 + 1e-9) + detail::kClearanceRounding * scale;
}

double SelfCore::end_reach(const BvhNode& n) const {
  double scale = 0;
  for (int k = 0; k < 3; ++k)
    scale = std::max({scale, std::abs(n.lo[k]), std::abs(n.hi[k])});
  return opt.reuse_distance * (1 + 1e-9) + detail::kClearanceRounding * scale;
}

bool SelfCore::corners_clear(const BvhNode& n, double cosine, double reach,
                             double end_reach) const {
  const auto& prims = bvh.prim_ids();
  const auto& faces = topo.faces();
  const bool at_end = end_reach >= 0;  // reach < 0 likewise: the step's test not asked
  for (int k = n.first; k < n.first + n.count; ++k) {
    const Face& f = faces[prims[k]];
    const auto x0 = ccd_detail::corners(v0, f), x1 = ccd_detail::corners(v1, f);
    // Both bounds from one pass over the corners; the exact clearances only where one fails.
    const detail::CornerBounds b = detail::triangle_corner_clearance_bounds(x0, x1);
    if (reach >= 0 && !(cosine * b.step > reach) &&
        !(cosine * detail::triangle_corner_clearance(x0, x1) > reach)) {
      return false;
    }
    if (at_end && !(cosine * b.end > end_reach) &&
        !(cosine * detail::triangle_corner_clearance(x1, x1) > end_reach)) {
      return false;
    }
  }
  return true;
}

bool SelfCore::culls(Rule mode, int i, detail::TraversalCounters& c) const {
  if (!cones_used(mode)) return false;
  const BvhNode& n = bvh.nodes()[i];
  if (mode == Rule::Gated && !n.connected()) return false;
  if (mode == Rule::Sound && (!n.disk() || n.count < opt.cull_min_triangles)) return false;
  ++c.cone_tests;
  const NormalCone& k = bvh.cones()[i];
  if (!(k.half_angle < std::numbers::pi / 2 - kConeMargin)) return false;
  if (mode != Rule::Sound) return true;
  ++c.contour_tests;
  // The star test is O(contour); the general simplicity test catches what it cannot.
  bool ok = detail::contour_star_shaped(bvh.contour(i), v0, v1, k.axis) ||
            detail::contour_simple(bvh.contour(i), v0, v1, k.axis);
  if (ok && culls_with_reach()) {
    // Projected distances are at least cos(half angle) times the 3-D corner clearances. The
    // step's features against the kernels' reach; where the pairs are kept, also the step's end
    // alone (the positions a later proximity query reuses) against the reuse distance. At
    // thickness 0 the contour test has settled the step already.
    const double reach = opt.thickness > 0 ? cull_reach(n) : -1.0;
    const double at_end = keeps() && !restricted ? end_reach(n) : -1.0;
    const double cosine = std::cos(k.half_angle);
    const std::span<const int> loop = bvh.contour(i);
    ok = corners_clear(n, cosine, reach, at_end) &&
         (at_end < 0 || detail::contour_clear(loop, v1, v1, k.axis, at_end)) &&
         (reach < 0 || detail::contour_clear(loop, v0, v1, k.axis, reach));
  }
  if (!ok) ++c.contour_fails;
  return ok;
}

void SelfCore::record_traversal(const detail::TraversalCounters& c, bool from_front,
                                const PairLocals& locals, DetectStats& st) const {
  st.box_tests = c.box_tests;
  st.nodes_culled = c.culled;
  st.cone_tests = c.cone_tests;
  st.contour_tests = c.contour_tests;
  st.contour_fails = c.contour_fails;
  st.front_pairs = from_front ? front.size() : 0;
  for (const auto& l : locals)
    st.adjacent_pairs += l.adjacent;
}

detail::PairList SelfCore::traverse(Rule mode, Scope scope, DetectStats& st, PairLocals& locals,
                                    bool from_front) {
  for (PairBuffer& l : locals) {
    l.pairs.clear();
    l.adjacent = 0;
  }
  detail::PairList pairs;
  if (bvh.nodes().empty()) return pairs;
  const detail::TraversalCounters c =
      from_front ? traverse_front(mode, locals) : traverse_root(mode, scope, locals);
  record_traversal(c, from_front, locals, st);
  for (const auto& l : locals)
    pairs.add(l.pairs);
  return pairs;
}

void SelfCore::traverse_each(Rule mode, Scope scope, DetectStats& st, PairLocals& locals,
                             bool from_front,
                             const std::function<void(const detail::PairList&)>& round) {
  const std::size_t rounds = from_front ? 1 : traversal_rounds();
  auto t = Clock::now();
  if (rounds == 1 || bvh.nodes().empty()) {
    const detail::PairList pairs = traverse(mode, scope, st, locals, from_front);
    st.time_traverse = seconds_since(t);
    round(pairs);
    return;
  }
  for (PairBuffer& l : locals) {
    l.pairs.clear();
    l.adjacent = 0;
  }
  double in_rounds = 0;
  const detail::TraversalCounters c = traverse_root(mode, scope, locals, rounds, [&] {
    const auto t0 = Clock::now();
    detail::PairList part;
    for (const auto& l : locals)
      part.add(l.pairs);
    round(part);
    for (PairBuffer& l : locals)
      l.pairs.clear();
    in_rounds += seconds_since(t0);
  });
  record_traversal(c, false, locals, st);
  st.time_traverse = seconds_since(t) - in_rounds;
}

detail::TraversalCounters SelfCore::traverse_root(Rule mode, Scope scope, PairLocals& locals,
                                                  std::size_t rounds,
                                                  const std::function<void()>& after_round) {
  const auto& nodes = bvh.nodes();
  auto cull = [&](int i, detail::TraversalCounters& c) { return culls(mode, i, c); };
  std::span<const std::uint8_t> act;
  if (scope == Scope::Active) act = node_active;
  auto tr = detail::make_traversal(nodes, nodes, act, act, cull, leaf_step());
  return detail::run_parallel(tr, {0, 0, true}, locals, rounds, [&] {
    if (after_round) after_round();
  });
}

detail::TraversalCounters SelfCore::traverse_front(Rule mode, PairLocals& locals) {
  const auto& nodes = bvh.nodes();
  front_live.assign(nodes.size(), 0);
  front_live[0] = 1;
  tbb::enumerable_thread_specific<detail::TraversalCounters> counters;
  const auto& levels = bvh.level_offsets();
  for (std::size_t d = 0; d + 1 < levels.size(); ++d) {
    tbb::parallel_for(tbb::blocked_range<int>(levels[d], levels[d + 1], 64),
                      [&](const tbb::blocked_range<int>& r) {
                        detail::TraversalCounters& c = counters.local();
                        for (int i = r.begin(); i != r.end(); ++i) {
                          const BvhNode& n = nodes[i];
                          if (front_live[i] == 0 || n.is_leaf()) continue;
                          if (culls(mode, i, c)) {
                            ++c.culled;
                            continue;
                          }
                          front_live[i] |= 2;
                          front_live[n.left] = front_live[n.left + 1] = 1;
                        }
                      });
  }
  if (front.empty()) {
    std::vector<detail::TraversalFront::Root> roots;
    for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
      if (!nodes[i].is_leaf()) roots.push_back({i, nodes[i].left, nodes[i].left + 1});
    }
    front.seed(roots);
  }
  detail::TraversalCounters c;
  for (const auto& k : counters)
    c.add(k);
  c.box_tests = front.run(
      bvh, bvh, [&](int n) { return (front_live[n] & 2) != 0; }, leaf_step(), locals);
  return c;
}

}  // namespace clothcd::detail
