#pragma once
// The self detector's state and stages (SelfDetector's implementation): one mesh state
// (mesh_state.hpp) and the stages a detection runs through it in order: refit (detector.cpp),
// culled traversal (self_traverse.cpp), narrow phase over the triangle pairs (the pair loop of
// pair_loop.hpp) and the orphans (self_narrow.cpp), finish. proximity() lives in
// self_proximity.cpp. The research module (src/research) drives the same stages with its unsound
// rules, optimal cones and many configurations at once.

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "bvh/front.hpp"
#include "bvh/traversal.hpp"
#include "clothcd/detect/detector.hpp"
#include "detect/mesh_state.hpp"
#include "detect/narrow.hpp"
#include "detect/orphans.hpp"
#include "detect/pair_loop.hpp"
#include "detect/positions.hpp"

namespace clothcd::detail {

/// The node test of a self traversal: Culling::None and Sound, and the research module's unsound
/// rules (the paper's cone rule, and the same on edge-connected nodes only).
enum class CullRule { None, Cone, Gated, Sound };

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

/// One thread's share of a traversal: its leaf pairs and the adjacent ones it skipped.
struct PairBuffer {
  PairBlocks pairs;
  std::uint64_t adjacent = 0;
};
using PairLocals = tbb::enumerable_thread_specific<PairBuffer>;

/// One thread's share of a CCD narrow phase: the pair loop's batches, and the feature pairs
/// queued for the batch filters and kernels.
struct NarrowBuffer : LoopBuffers {
  std::vector<VertexFaceCollision> vf;
  std::vector<EdgeEdgeCollision> ee;
  FeatureBatch batch;
};
using NarrowLocals = tbb::enumerable_thread_specific<NarrowBuffer>;

/// share_vertex(a, b) without its branches: the traversal asks it of every overlapping leaf pair,
/// and most share nothing.
[[nodiscard]] inline bool faces_touch(const Face& a, const Face& b) {
#if defined(__SSE2__)
  const __m128i vb = _mm_setr_epi32(b[0], b[1], b[2], b[2]);
  const __m128i eq = _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi32(vb, _mm_set1_epi32(a[0])),
                                               _mm_cmpeq_epi32(vb, _mm_set1_epi32(a[1]))),
                                  _mm_cmpeq_epi32(vb, _mm_set1_epi32(a[2])));
  return _mm_movemask_epi8(eq) != 0;
#else
  return share_vertex(a, b);
#endif
}

/// Refuses options the self detector cannot honour (InputError), before any work.
void check_self_options(const DetectOptions& o);
/// Refuses options naming a build other than the tree's (it is built once, at construction).
void check_same_build(BvhBuild built, BvhBuild asked, std::string_view call);

/// The self detector: one mesh state, the options, and what the culled traversal and the
/// proximity query keep from call to call.
struct SelfCore : MeshState {
  using Rule = CullRule;

  DetectOptions opt;
  Orphans orphans;
  // opt.linked_vertices normalized by the first detect() after construction or set_options (a
  // bad id throws there, and again at every call until the options change).
  std::vector<std::pair<int, int>> links;
  bool links_current = false;
  Ownership owner;
  // The traversal's pair blocks, kept from call to call (pair_list.hpp).
  PairLocals pair_locals;
  // Where the last unrestricted detect() with opt.reuse_front stopped below each internal node,
  // and which internal nodes' child pairs the current call traverses (front.hpp).
  TraversalFront front;
  std::vector<std::uint8_t> front_live;
  // The triangle pairs of the last unrestricted detect() with boxes widened to
  // opt.reuse_distance that are at most that far apart at t1 (the others' features are farther,
  // wherever their vertices still are), and its positions at t1: a proximity query at most that
  // far needs no traversal for the vertices still there (see DetectOptions::reuse_distance).
  struct Reuse {
    bool valid = false;
    std::vector<Eigen::Vector3d> x1;
    std::vector<std::pair<int, int>> pairs;
  } reuse;
  // The node test the traversal runs: opt.culling's, or a research rule set by the research
  // module; and whether the refit computes the optimal cones (research only).
  Rule cull = Rule::None;
  bool optimal_cones = false;

  SelfCore(std::vector<Face> faces, int nv, PointsIn ref, const DetectOptions& o);
  /// Replaces the options (checked; the build must stay) and resets what depended on them.
  void set_options(const DetectOptions& o);

  // opt.linked_vertices normalized, once per change of the options (throws for a bad id).
  void update_links() {
    if (links_current) return;
    links = sorted_links(opt.linked_vertices, topo.num_vertices());
    links_current = true;
  }
  [[nodiscard]] bool cones_used(Rule mode) const { return mode != Rule::None; }
  [[nodiscard]] Rule rule() const { return cull; }
  // Pairs kept for reuse: not with the unsound rules, which may cull close pairs. Sound culling
  // then certifies its nodes free of feature pairs within reuse_distance at t1 too (end_reach()),
  // so the list holds every overlapping leaf pair that can matter; the boxes reach
  // reuse_distance.
  [[nodiscard]] bool keeps() const {
    return opt.reuse_distance > 0 && (rule() == Rule::None || rule() == Rule::Sound);
  }
  [[nodiscard]] double box_reach() const {
    return keeps() ? std::max(opt.thickness, opt.reuse_distance) : opt.thickness;
  }
  // Sound culling with a contact distance (docs/algorithms.md 1.6): at thickness 0 and without
  // reuse, the contour test alone proves a node free of contacts; otherwise a node must also
  // keep its non-adjacent features farther apart than the node's reach over the step
  // (cull_reach(), at thickness > 0) and, where the pairs are kept, than the reuse distance at
  // t1 (end_reach(), a step without motion: each query at its own reach).
  [[nodiscard]] bool culls_with_reach() const {
    return rule() == Rule::Sound && (opt.thickness > 0 || keeps());
  }
  // How close two features of node n may come before the narrow phase could report them: a
  // kernel hit certifies a distance of at most sqrt(3) (thickness + tolerance * extent), the
  // extent being at most the node box's longest side.
  [[nodiscard]] double cull_reach(const BvhNode& n) const;
  // How close two features of node n may be at t1 before a later proximity query that takes
  // the kept pairs could report them: reuse_distance, widened for rounding like cull_reach().
  [[nodiscard]] double end_reach(const BvhNode& n) const;
  // Whether every triangle below node n keeps, over the current step, its corners more than
  // reach / cosine from their opposite sides (docs/algorithms.md 1.6): cosine times the smallest
  // corner clearance exceeds reach. Computed only for the nodes the traversal asks about (their
  // cones and contours passed), and the nodes it culls are disjoint, so a pass visits few
  // triangles more than once. A triangle's cheap lower bound settles most of them; the others
  // take the exact clearance, so the answer is the exact clearances' bit for bit.
  // With `end_reach` >= 0, also cosine times every corner's clearance at t1 alone exceeds
  // end_reach (the step-end test of end_reach()); either test is skipped where its reach is < 0.
  [[nodiscard]] bool corners_clear(const BvhNode& n, double cosine, double reach,
                                   double end_reach = -1) const;
  [[nodiscard]] bool vf_in_scope(Scope s, int v, int f) const {
    return s == Scope::All ||
           ((vertex_active[v] != 0 || face_active[f] != 0) == (s == Scope::Active));
  }
  [[nodiscard]] bool ee_in_scope(Scope s, int ea, int eb) const {
    return s == Scope::All ||
           ((edge_active[ea] != 0 || edge_active[eb] != 0) == (s == Scope::Active));
  }
  // Whether the self test of internal node i is skipped under `mode` (the cones of the last
  // refit): counts the cone and contour tests it makes.
  bool culls(Rule mode, int i, TraversalCounters& c) const;
  // The traversals' step at an overlapping leaf pair: its faces' pair, unless they share a
  // vertex (left to the orphans, only counted). Plain pointers: the output's stores could
  // otherwise alias the containers.
  [[nodiscard]] auto leaf_step() const {
    // The corners in tree order (prim_faces): neighbouring leaves' faces sit together there,
    // wherever their ids are.
    return [np = bvh.nodes().data(), pp = bvh.prim_ids().data(), pf = bvh.prim_faces().data()](
               int a, int b, PairBuffer& out) {
      const int ia = np[a].first, ib = np[b].first;
      if (faces_touch(pf[ia], pf[ib])) {
        ++out.adjacent;
        return;
      }
      out.pairs.push(pp[ia], pp[ib]);
    };
  }
  // Overlapping non-adjacent leaf pairs of the culled self traversal, held in `locals` (emptied
  // first) until the next traversal into them; below the active nodes only for Scope::Active.
  // `from_front` (Scope::All only): from the front of the last call that used one, which it
  // replaces (DetectOptions::reuse_front): the same leaf pairs and self tests; only the pairs'
  // order and the box tests differ.
  PairList traverse(Rule mode, Scope scope, DetectStats& st, PairLocals& locals,
                    bool from_front = false);
  // traverse()'s pairs handed to round(pairs) a part at a time, `locals` emptied after each: on a
  // large mesh the walk from the root runs in rounds of its tasks (traversal_rounds()), and only
  // one round's pairs are held at once (millions of pairs otherwise: 250 MB for a proximity
  // query on 4M triangles). The same pairs, box tests and culls as traverse(), and its stats;
  // st.time_traverse is the walk's time, round()'s excluded.
  void traverse_each(Rule mode, Scope scope, DetectStats& st, PairLocals& locals, bool from_front,
                     const std::function<void(const PairList&)>& round);
  // The rounds of traverse_each()'s walk from the root: one up to 2^18 triangles (whose pairs
  // take a few MB), then one per 2^18 triangles, at most 16.
  [[nodiscard]] std::size_t traversal_rounds() const {
    return std::clamp<std::size_t>(static_cast<std::size_t>(topo.num_faces()) >> 18, 1, 16);
  }
  // traverse()'s walk from the root, in parallel over a frontier of tasks; in `rounds` rounds
  // of them, after_round() after each (run_parallel).
  TraversalCounters traverse_root(Rule mode, Scope scope, PairLocals& locals,
                                  std::size_t rounds = 1,
                                  const std::function<void()>& after_round = {});
  // The traversal's counters and the adjacent pairs of `locals` into `st`.
  void record_traversal(const TraversalCounters& c, bool from_front, const PairLocals& locals,
                        DetectStats& st) const;
  // traverse()'s walk from the front: first the self tests the walk from the root makes, a level
  // at a time (bit 0 of front_live[n]: the self test of n runs, its parent's did and was not
  // culled; bit 1: n is internal and not culled, so the pairs of its children are traversed),
  // then the front of every internal node, from its children pair on the first call.
  TraversalCounters traverse_front(Rule mode, PairLocals& locals);
  [[nodiscard]] FeatureContext ccd_context() const {
    return detail::ccd_context(topo, v0, v1, opt, links);
  }
  // The feature pairs of `pairs` and of the orphans that collide (ctx's boxes are up to date).
  // With `near`, also flags the pairs whose faces are at most opt.reuse_distance apart at t1.
  void narrow(const FeatureContext& ctx, const PairList& pairs, Scope scope, DetectResult& res,
              std::vector<std::uint8_t>* near = nullptr);
  // The feature pairs of the triangle pairs `pairs` that collide, into `locals`.
  void narrow_pairs(const FeatureContext& ctx, const PairList& pairs, Scope scope,
                    NarrowLocals& locals, std::vector<std::uint8_t>* near = nullptr) const;
  // The orphan feature pairs that collide, into `locals`.
  void narrow_orphans(const FeatureContext& ctx, Scope scope, NarrowLocals& locals) const;
  // The in-scope orphan pairs whose boxes overlap, to kvf(v, f, t, out) and kee(a, b, ea, eb,
  // out), `out` a thread's buffer of `locals`.
  template <class Locals, class KernelVf, class KernelEe>
  void orphan_pairs(const FeatureContext& ctx, Scope scope, Locals& locals, KernelVf&& kvf,
                    KernelEe&& kee) const {
    const auto& faces = topo.faces();
    const auto& edges = topo.edges();
    const auto each = [&](const std::vector<std::pair<int, int>>& list, auto&& test) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, list.size(), 256),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          auto& out = locals.local();
                          for (std::size_t i = r.begin(); i != r.end(); ++i)
                            test(list[i].first, list[i].second, out);
                        });
    };
    each(orphans.vf, [&](int v, int f, auto& out) {
      if (vf_in_scope(scope, v, f) && overlap(ctx.vertex_box(v), ctx.face_box(f))) {
        kvf(v, f, faces[f], out);
      }
    });
    each(orphans.ee, [&](int ea, int eb, auto& out) {
      if (ee_in_scope(scope, ea, eb) && overlap(ctx.edge_box(ea), ctx.edge_box(eb))) {
        kee(ea, eb, edges[ea], edges[eb], out);
      }
    });
  }
  // Adds the buffers' counters and collisions to `res` (left unsorted).
  static void gather(const NarrowLocals& locals, DetectResult& res);
  // Sorts the collisions and counts them, and the orphans every detection checks.
  void finish(DetectResult& res) const;
  // Tests the feature pairs of a non-adjacent triangle pair whose representative pair it is.
  // Needs the context's precomputed boxes and face blocks (`boxes` keeps both).
  template <class Out, class KernelVf, class KernelEe>
  void triangle_pair(const FeatureContext& ctx, Scope scope, int f, int g, Out& out, KernelVf&& kvf,
                     KernelEe&& kee) const {
    owned_feature_pairs(
        owner, StepFaceBoxes{ctx}, f, g,
        [&](int v, int face, const Face& t) {
          if (vf_in_scope(scope, v, face)) kvf(v, face, t, out);
        },
        [&](int e1, int e2, const Edge& a, const Edge& b) {
          if (ee_in_scope(scope, e1, e2)) kee(e1, e2, a, b, out);
        });
  }
  // The pair loop's sides (both this mesh) for the context's positions and boxes.
  [[nodiscard]] LoopSide loop_side(const FeatureContext& ctx) const {
    return {ctx.v0, ctx.v1, &topo.faces(), ctx.face_boxes, ctx.fboxes};
  }
  // The pair loop's prefetch of faces f's and g's ownership records and box blocks. Always
  // inlined: to the compiler a call of a function that only prefetches has no effect, and it
  // deletes the call.
  [[nodiscard]] auto fetch(const FeatureContext& ctx) const {
    return [ this, &ctx ](int f, int g) __attribute__((always_inline)) {
      for (int h : {f, g}) {
        prefetch(&owner.record(h));
        const auto* block = reinterpret_cast<const char*>(&ctx.face_boxes[h]);
        for (int line = 0; line < 3; ++line)
          prefetch(block + 64 * line);
      }
    };
  }
  // Boxes and cones for the current options, where vertices moved since the last refit (all of
  // it when the refit options changed).
  void refit(DetectStats& st);
  // `kernels` false: every pair the filters keep is a hit at time 0 (FilterPlan::kernel), for
  // the earliest-impact query's windows.
  DetectResult detect(PointsIn p0, PointsIn p1, bool kernels = true);
  ProximityResult proximity(PointsIn p, double h);
  // detect() over time windows, reduced to the earliest hit (earliest.cpp).
  EarliestImpact earliest_impact(PointsIn p0, PointsIn p1, const EarliestOptions& o);
  // Whether proximity(v0, h) can use the kept pairs: then the active restriction is set to the
  // vertices that moved since (few, or the traversal is cheaper). `reuse.valid` implies keeps():
  // only detect() sets it, and set_options() clears it.
  bool reusable(double h);
};

/// The core of a SelfDetector, for the research module (src/research), which drives its stages.
struct SelfAccess {
  static SelfCore& core(SelfDetector& d) { return *d.impl_; }
  static const SelfCore& core(const SelfDetector& d) { return *d.impl_; }
};

}  // namespace clothcd::detail
