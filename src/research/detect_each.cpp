// SelfDetector::detect_each of the research module: many configurations of one step, the node
// pairs' box tests and the narrow phase shared between the configurations that keep them.

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "detect/self_core.hpp"
#include "research/core_options.hpp"

namespace clothcd::research {
namespace {

// detect_each's walk of each configuration's rule over the nodes: refits to its cones (the
// detector's options become configs[k], built as `build`), counts the rule's tests into
// out[k].stats, and sets bit k of the result's entry n when the self test of internal node n
// runs under configs[k], so that the pair traversal of n's children does.
std::vector<std::uint64_t> kept_nodes(detail::SelfCore& m, std::span<const DetectOptions> configs,
                                      BvhBuild build, std::vector<clothcd::DetectResult>& out) {
  const auto& nodes = m.bvh.nodes();
  std::vector<std::uint64_t> keep(nodes.size(), 0);
  std::vector<int> stack;
  for (std::size_t k = 0; k < configs.size(); ++k) {
    use(m, configs[k]);
    m.opt.build = build;
    DetectStats& st = out[k].stats;
    m.refit(st);
    const detail::CullRule mode = m.rule();
    detail::TraversalCounters c;
    if (!nodes.empty()) stack.assign(1, 0);
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      if (nodes[i].is_leaf()) continue;
      if (m.culls(mode, i, c)) {
        ++c.culled;
        continue;
      }
      keep[i] |= std::uint64_t{1} << k;
      stack.push_back(nodes[i].left + 1);
      stack.push_back(nodes[i].left);
    }
    st.nodes_culled = c.culled;
    st.cone_tests = c.cone_tests;
    st.contour_tests = c.contour_tests;
    st.contour_fails = c.contour_fails;
    st.time_traverse = std::nan("");
    st.time_narrow = std::nan("");
  }
  return keep;
}

// Adds the shared work's counters and collisions (a group's or the orphans') to a result.
void add_shared(const clothcd::DetectResult& from, clothcd::DetectResult& to) {
  DetectStats& s = to.stats;
  const DetectStats& f = from.stats;
  s.box_tests += f.box_tests;
  s.adjacent_pairs += f.adjacent_pairs;
  s.triangle_pairs += f.triangle_pairs;
  s.triangle_pairs_apart += f.triangle_pairs_apart;
  s.vf_tests += f.vf_tests;
  s.ee_tests += f.ee_tests;
  s.vf_np_culled += f.vf_np_culled;
  s.ee_np_culled += f.ee_np_culled;
  to.vf.insert(to.vf.end(), from.vf.begin(), from.vf.end());
  to.ee.insert(to.ee.end(), from.ee.begin(), from.ee.end());
}

}  // namespace

// The self traversal without culling is the union, over the internal nodes n, of the pair
// traversals of n's two children: every leaf pair below n whose leaves lie on either side of the
// split. A culling rule removes exactly the pair traversals of the nodes it culls and of their
// descendants. So each configuration walks its rule over the nodes (refit to its cones), which
// marks the nodes whose pair traversal it keeps; the nodes are grouped by the set of
// configurations that keep them; and each group's pair traversals and narrow phase run once,
// their counters and collisions going to every configuration of its set.
std::vector<clothcd::DetectResult> detect_each_on(detail::SelfCore& m, detail::PointsIn p0,
                                                  detail::PointsIn p1,
                                                  std::span<const DetectOptions> configs) {
  constexpr std::size_t kMaxConfigs = 64;
  if (configs.size() > kMaxConfigs) {
    throw InputError(
        fmt::format("detect_each: {} configurations, at most {}", configs.size(), kMaxConfigs));
  }
  if (m.restricted) throw InputError("detect_each: clear the active restriction first");
  // Everything but the culling and the cones must match: boxes, kernels and links are shared.
  auto shared_part = [](DetectOptions o) {
    o.policy = {};
    o.culling = {};
    o.build = {};
    o.cull_min_triangles = 0;
    o.research.culling.reset();
    o.research.optimal_cones = false;
    return o;
  };
  for (std::size_t k = 0; k < configs.size(); ++k) {
    const DetectOptions& c = configs[k];
    detail::check_self_options(c);
    check_research(c);
    detail::check_same_build(m.opt.build, c.build, fmt::format("detect_each: configuration {}", k));
    if (c.reuse_distance != 0 || c.research.verify) {
      throw InputError(fmt::format(
          "detect_each: configuration {} sets reuse_distance or verify (both must be off)", k));
    }
    if (!(shared_part(c) == shared_part(configs[0]))) {
      throw InputError(fmt::format(
          "detect_each: configuration {} differs from the first in more than its policy, "
          "culling, cull_min_triangles, unsound culling or optimal cones",
          k));
    }
  }
  std::vector<clothcd::DetectResult> out(configs.size());
  if (configs.empty()) return out;
  // The caller's options come back however this ends.
  struct Restore {
    detail::SelfCore& im;
    clothcd::DetectOptions saved;
    detail::CullRule cull;
    bool optimal;
    ~Restore() {
      im.opt = std::move(saved);
      im.cull = cull;
      im.optimal_cones = optimal;
      im.links_current = false;
    }
  } restore{m, m.opt, m.cull, m.optimal_cones};
  m.reuse.valid = false;
  m.step.update(p0, p1, m.topo.num_vertices(), "positions at t0", "positions at t1");
  use(m, configs[0]);
  m.opt.build = restore.saved.build;
  m.links_current = false;
  m.update_links();

  const std::vector<std::uint64_t> keep = kept_nodes(m, configs, restore.saved.build, out);
  const auto& nodes = m.bvh.nodes();

  // Groups: the distinct sets of configurations, and the pair traversals of each group's nodes.
  std::vector<std::uint64_t> sets;
  std::vector<int> group(nodes.size(), -1);
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    if (keep[n] == 0) continue;
    auto it = std::find(sets.begin(), sets.end(), keep[n]);
    group[n] = static_cast<int>(it - sets.begin());
    if (it == sets.end()) sets.push_back(keep[n]);
  }
  const std::size_t ng = sets.size();
  struct GroupPairs {
    detail::PairBlocks pairs;
    std::uint64_t adjacent = 0, box_tests = 0;
  };
  struct Local {
    int g = 0;  // the group of the pair traversal running
    std::vector<GroupPairs> groups;
  };
  auto no_cull = [](int, detail::TraversalCounters&) { return false; };
  auto leaf = [np = nodes.data(), pp = m.bvh.prim_ids().data(), pf = m.bvh.prim_faces().data()](
                  int a, int b, Local& out) {
    GroupPairs& gp = out.groups[out.g];
    const int ia = np[a].first, ib = np[b].first;
    if (detail::faces_touch(pf[ia], pf[ib])) {
      ++gp.adjacent;
      return;
    }
    gp.pairs.push(pp[ia], pp[ib]);
  };
  auto tr = detail::make_traversal(nodes, nodes, {}, {}, no_cull, leaf);
  tbb::enumerable_thread_specific<Local> locals([ng] {
    Local l;
    l.groups.resize(ng);
    return l;
  });
  // Each kept node's pair traversal, those of large nodes split a few levels first (as
  // run_parallel splits the root) so that the threads share them.
  std::vector<std::pair<detail::Task, int>> tasks;
  {
    Local& serial = locals.local();
    const int big = std::max(64, m.topo.num_faces() / 64);
    std::vector<std::pair<detail::Task, int>> todo;
    for (std::size_t n = 0; n < nodes.size(); ++n) {
      if (group[n] >= 0)
        todo.emplace_back(detail::Task{nodes[n].left, nodes[n].left + 1, false}, group[n]);
    }
    while (!todo.empty()) {
      // Named copies: a lambda below captures g (not a structured binding: C++20 compilers
      // differ on capturing those).
      const detail::Task t = todo.back().first;
      const int g = todo.back().second;
      todo.pop_back();
      if (std::min(nodes[t.a].count, nodes[t.b].count) <= big) {
        tasks.emplace_back(t, g);
        continue;
      }
      // step() tests the pair's boxes and leaves its children untested: run() tests them.
      detail::TraversalCounters c;
      serial.g = g;
      tr.step(t, c, serial, [&](const detail::Task& s) { todo.emplace_back(s, g); });
      serial.groups[static_cast<std::size_t>(g)].box_tests += c.box_tests;
    }
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tasks.size(), 8),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      Local& l = locals.local();
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const auto& [t, g] = tasks[i];
                        detail::TraversalCounters c;
                        l.g = g;
                        tr.run(t, c, l);
                        l.groups[static_cast<std::size_t>(g)].box_tests += c.box_tests;
                      }
                    });

  // The narrow phase of each group, then the orphans, which every configuration checks.
  detail::FeatureContext ctx = m.ccd_context();
  m.boxes.update(ctx, m.step);
  std::vector<clothcd::DetectResult> found(ng);
  for (std::size_t g = 0; g < ng; ++g) {
    detail::NarrowLocals narrow_locals;
    for (Local& l : locals) {
      GroupPairs& gp = l.groups[g];
      found[g].stats.box_tests += gp.box_tests;
      found[g].stats.adjacent_pairs += gp.adjacent;
      detail::PairList list;
      list.add(gp.pairs);
      m.narrow_pairs(ctx, list, detail::Scope::All, narrow_locals);
    }
    m.gather(narrow_locals, found[g]);
  }
  clothcd::DetectResult orphan_hits;
  {
    detail::NarrowLocals narrow_locals;
    m.narrow_orphans(ctx, detail::Scope::All, narrow_locals);
    m.gather(narrow_locals, orphan_hits);
  }
  for (std::size_t k = 0; k < configs.size(); ++k) {
    for (std::size_t g = 0; g < ng; ++g) {
      if ((sets[g] >> k) & 1U) add_shared(found[g], out[k]);
    }
    add_shared(orphan_hits, out[k]);
    m.finish(out[k]);
  }
  return out;
}

}  // namespace clothcd::research
