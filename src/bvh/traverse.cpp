// The public traversals (clothcd/bvh/traverse.hpp): the module's traversal template
// (traversal.hpp, which the detectors run with their culling) without culling or active
// restriction.

#include "clothcd/bvh/traverse.hpp"

#include <tbb/enumerable_thread_specific.h>

#include "bvh/traversal.hpp"

namespace clothcd {
namespace {

using Pairs = std::vector<std::pair<int, int>>;

// The traversal of na x nb (one tree twice for a self traversal), handing face ids to `emit`.
template <class Emit>
auto face_traversal(const Bvh& a, const Bvh& b, Emit emit) {
  const BvhNode* na = a.nodes().data();
  const BvhNode* nb = b.nodes().data();
  const int* pa = a.prim_ids().data();
  const int* pb = b.prim_ids().data();
  auto no_cull = [](int, detail::TraversalCounters&) { return false; };
  auto leaf = [=](int i, int j, auto& local) { emit(pa[na[i].first], pb[nb[j].first], local); };
  return detail::make_traversal(a.nodes(), b.nodes(), {}, {}, no_cull, leaf);
}

struct NoLocal {};

void run_serial(const Bvh& a, const Bvh& b, bool self, const LeafPairFn& on_leaf_pair) {
  if (a.nodes().empty() || b.nodes().empty()) return;
  const auto tr = face_traversal(a, b, [&](int f, int g, NoLocal&) { on_leaf_pair(f, g); });
  detail::TraversalCounters c;
  NoLocal local;
  tr.run(detail::Task{0, 0, self}, c, local);
}

Pairs collect_parallel(const Bvh& a, const Bvh& b, bool self) {
  Pairs out;
  if (a.nodes().empty() || b.nodes().empty()) return out;
  const auto tr =
      face_traversal(a, b, [](int f, int g, Pairs& local) { local.emplace_back(f, g); });
  tbb::enumerable_thread_specific<Pairs> locals;
  detail::run_parallel(tr, detail::Task{0, 0, self}, locals);
  std::size_t total = 0;
  for (const Pairs& l : locals)
    total += l.size();
  out.reserve(total);
  for (const Pairs& l : locals)
    out.insert(out.end(), l.begin(), l.end());
  return out;
}

}  // namespace

void self_traverse(const Bvh& bvh, const LeafPairFn& on_leaf_pair) {
  run_serial(bvh, bvh, true, on_leaf_pair);
}

void pair_traverse(const Bvh& a, const Bvh& b, const LeafPairFn& on_leaf_pair) {
  run_serial(a, b, false, on_leaf_pair);
}

std::vector<std::pair<int, int>> overlapping_leaf_pairs(const Bvh& bvh) {
  return collect_parallel(bvh, bvh, true);
}

std::vector<std::pair<int, int>> overlapping_leaf_pairs(const Bvh& a, const Bvh& b) {
  return collect_parallel(a, b, false);
}

}  // namespace clothcd
