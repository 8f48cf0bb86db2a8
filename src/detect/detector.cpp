// The self-collision detector: refit, culled self traversal, narrow phase over representative
// triangle pairs and orphans.

#include "clothcd/detect/detector.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "ccd/distances.hpp"
#include "clearance.hpp"
#include "clothcd/ccd/proximity.hpp"
#include "clothcd/detect/names.hpp"
#include "clothcd/research/names.hpp"
#include "contour.hpp"
#include "front.hpp"
#include "narrow.hpp"
#include "options.hpp"
#include "orphans.hpp"
#include "pair_list.hpp"
#include "positions.hpp"
#include "traversal.hpp"

namespace clothcd {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Cones are compared against pi/2 with a small margin for the rounding of the merges.
constexpr double kConeMargin = 1e-9;

// One thread's share of a traversal: its leaf pairs and the adjacent ones it skipped.
struct PairBuffer {
  detail::PairBlocks pairs;
  std::uint64_t adjacent = 0;
};
using PairLocals = tbb::enumerable_thread_specific<PairBuffer>;

// detail::share_vertex(a, b) without its branches: the traversal asks it of every overlapping
// leaf pair, and most share nothing.
[[nodiscard]] inline bool faces_touch(const Face& a, const Face& b) {
#if defined(__SSE2__)
  const __m128i vb = _mm_setr_epi32(b[0], b[1], b[2], b[2]);
  const __m128i eq = _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi32(vb, _mm_set1_epi32(a[0])),
                                               _mm_cmpeq_epi32(vb, _mm_set1_epi32(a[1]))),
                                  _mm_cmpeq_epi32(vb, _mm_set1_epi32(a[2])));
  return _mm_movemask_epi8(eq) != 0;
#else
  return detail::share_vertex(a, b);
#endif
}

// Options the detector cannot honour are refused before any work.
void check_options(const DetectOptions& o) {
  detail::check_common_options(o);
  if (!(o.reuse_distance >= 0) || !std::isfinite(o.reuse_distance)) {
    throw InputError(
        fmt::format("reuse distance must be finite and >= 0, got {}", o.reuse_distance));
  }
  if (o.cull_min_triangles < 0) {
    throw InputError(fmt::format("cull_min_triangles must be >= 0, got {}", o.cull_min_triangles));
  }
  if (o.reuse_distance > 0 && o.research.unsound_culling != research::UnsoundCulling::None) {
    throw InputError(
        "reuse distance: the unsound culling rules may cull the pairs it keeps; use culling none "
        "or sound with it");
  }
}

// The tree is built once, at construction: options naming another build are refused.
void check_same_build(BvhBuild built, BvhBuild asked, std::string_view call) {
  if (asked != built) {
    throw InputError(fmt::format(
        "{}: the BVH build is fixed at construction ({}), got {}; construct a detector for "
        "another build",
        call, to_string(built), to_string(asked)));
  }
}

struct NarrowBuffer {
  detail::FeatureCounters c;
  std::vector<VertexFaceCollision> vf;
  std::vector<EdgeEdgeCollision> ee;
  detail::FeatureBatch batch;     // the pair loop's feature pairs, NP-filtered a batch at a time
  detail::FacesApartBatch faces;  // its triangle pairs, distance-filtered a batch at a time
  detail::FaceBoundBatch near;    // ... those whose boxes miss, bounded at t1 a batch at a time
};

}  // namespace

struct SelfDetector::Impl {
  // The traversal's culling rule: any of the four, the research options' unsound ones included.
  using Rule = research::CullingRule;

  Topology topo;
  DetectOptions opt;
  Bvh bvh;
  detail::Orphans orphans;
  // The positions of the last call, and which vertices changed since the call before: one copy
  // and one comparison a call, shared by the refit and the feature boxes.
  detail::StepPositions step;
  const std::vector<Eigen::Vector3d>& v0 = step.x0();
  const std::vector<Eigen::Vector3d>& v1 = step.x1();
  std::uint64_t bvh_call = 0;  // the call of `step` the tree was last swept at (0: none)
  // Active restriction: features on active faces, and the nodes holding a face that touches one.
  // `outside` turns it into its complement (the pairs the restriction leaves out).
  bool restricted = false;
  bool outside = false;
  std::vector<std::uint8_t> face_active, vertex_active, edge_active, node_active;
  // Swept boxes of the features, updated where vertices moved (see FeatureBoxes), also gathered
  // per face for the pair loop.
  detail::FeatureBoxes boxes{true};
  // opt.linked_vertices normalized by the first detect() after construction or set_options (a
  // bad id throws there, and again at every call until the options change).
  std::vector<std::pair<int, int>> links;
  bool links_current = false;
  detail::Ownership owner;
  // The traversal's pair blocks, kept from call to call (pair_list.hpp).
  PairLocals pair_locals;
  // Where the last unrestricted detect() with opt.reuse_front stopped below each internal node,
  // and which internal nodes' child pairs the current call traverses (front.hpp).
  detail::TraversalFront front;
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

  Impl(std::vector<Face> faces, int nv, detail::PointsIn ref, const DetectOptions& o)
      : topo(std::move(faces), nv), opt(o) {
    check_options(o);
    std::vector<Eigen::Vector3d> reference;
    detail::to_points(ref, nv, "reference shape", reference);
    bvh = Bvh(topo, reference, o.build);
    orphans = detail::find_orphans(topo);
    owner = detail::Ownership(topo);
  }

  // opt.linked_vertices normalized, once per change of the options (throws for a bad id).
  void update_links() {
    if (links_current) return;
    links = detail::sorted_links(opt.linked_vertices, topo.num_vertices());
    links_current = true;
  }

  [[nodiscard]] bool cones_used(Rule mode) const { return mode != Rule::None; }
  [[nodiscard]] Rule rule() const { return research::culling_rule(opt); }

  // Pairs kept for reuse: not with the unsound rules, which may cull close pairs. Sound culling
  // then certifies its nodes free of feature pairs within reuse_distance too (cull_reach()), so
  // the list holds every overlapping leaf pair that can matter; the boxes reach reuse_distance.
  [[nodiscard]] bool keeps() const {
    return opt.reuse_distance > 0 && (rule() == Rule::None || rule() == Rule::Sound);
  }
  [[nodiscard]] double box_reach() const {
    return keeps() ? std::max(opt.thickness, opt.reuse_distance) : opt.thickness;
  }

  // Sound culling with a contact distance (docs/algorithms.md 1.6): at thickness 0 and without
  // reuse, the contour test alone proves a node free of contacts; otherwise a node must also
  // keep its non-adjacent features farther apart than the node's reach.
  [[nodiscard]] bool culls_with_reach() const {
    return rule() == Rule::Sound && (opt.thickness > 0 || keeps());
  }

  // How close two features of node n may come before the narrow phase could report them: a
  // kernel hit certifies a distance of at most sqrt(3) (thickness + tolerance * extent), the
  // extent being at most the node box's longest side; a kept pair matters within reuse_distance.
  [[nodiscard]] double cull_reach(const BvhNode& n) const {
    double extent = 0, scale = 0;
    for (int k = 0; k < 3; ++k) {
      extent = std::max(extent, n.hi[k] - n.lo[k]);
      scale = std::max({scale, std::abs(n.lo[k]), std::abs(n.hi[k])});
    }
    const double kernel = std::sqrt(3.0) * (opt.thickness + CcdOptions{}.tolerance * extent);
    const double reach = std::max(kernel, keeps() ? opt.reuse_distance : 0.0);
    return reach * (1 + 1e-9) + detail::kClearanceRounding * scale;
  }

  // Whether every triangle below node n keeps, over the current step, its corners more than
  // reach / cosine from their opposite sides (docs/algorithms.md 1.6): cosine times the smallest
  // corner clearance exceeds reach. Computed only for the nodes the traversal asks about (their
  // cones and contours passed), and the nodes it culls are disjoint, so a pass visits few
  // triangles more than once. A triangle's cheap lower bound settles most of them; the others
  // take the exact clearance, so the answer is the exact clearances' bit for bit.
  [[nodiscard]] bool corners_clear(const BvhNode& n, double cosine, double reach) const {
    const auto& prims = bvh.prim_ids();
    const auto& faces = topo.faces();
    for (int k = n.first; k < n.first + n.count; ++k) {
      const Face& f = faces[prims[k]];
      const auto x0 = detail::corners(v0, f), x1 = detail::corners(v1, f);
      if (cosine * detail::triangle_corner_clearance_bound(x0, x1) > reach) continue;
      if (!(cosine * detail::triangle_corner_clearance(x0, x1) > reach)) return false;
    }
    return true;
  }

  [[nodiscard]] bool vf_in_scope(int v, int f) const {
    return !restricted || ((vertex_active[v] != 0 || face_active[f] != 0) != outside);
  }
  [[nodiscard]] bool ee_in_scope(int ea, int eb) const {
    return !restricted || ((edge_active[ea] != 0 || edge_active[eb] != 0) != outside);
  }

  // Whether the self test of internal node i is skipped under `mode` (the cones of the last
  // refit): counts the cone and contour tests it makes.
  bool culls(Rule mode, int i, detail::TraversalCounters& c) const {
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
      // Projected distances are at least cos(half angle) times the 3-D corner clearances.
      const double reach = cull_reach(n);
      const double cosine = std::cos(k.half_angle);
      ok = corners_clear(n, cosine, reach) &&
           detail::contour_clear(bvh.contour(i), v0, v1, k.axis, reach);
    }
    if (!ok) ++c.contour_fails;
    return ok;
  }

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
  // first) until the next traversal into them. `from_front` (unrestricted calls only): from the
  // front of the last call that used one, which it replaces (DetectOptions::reuse_front): the
  // same leaf pairs and self tests; only the pairs' order and the box tests differ.
  detail::PairList traverse(Rule mode, DetectStats& st, PairLocals& locals,
                            bool from_front = false) {
    for (PairBuffer& l : locals) {
      l.pairs.clear();
      l.adjacent = 0;
    }
    detail::PairList pairs;
    if (bvh.nodes().empty()) return pairs;
    const detail::TraversalCounters c =
        from_front ? traverse_front(mode, locals) : traverse_root(mode, locals);
    st.box_tests = c.box_tests;
    st.nodes_culled = c.culled;
    st.cone_tests = c.cone_tests;
    st.contour_tests = c.contour_tests;
    st.contour_fails = c.contour_fails;
    st.front_pairs = from_front ? front.size() : 0;
    for (const auto& l : locals) {
      pairs.add(l.pairs);
      st.adjacent_pairs += l.adjacent;
    }
    return pairs;
  }

  // traverse()'s walk from the root, in parallel over a frontier of tasks.
  detail::TraversalCounters traverse_root(Rule mode, PairLocals& locals) {
    const auto& nodes = bvh.nodes();
    auto cull = [&](int i, detail::TraversalCounters& c) { return culls(mode, i, c); };
    std::span<const std::uint8_t> act;
    if (restricted) act = node_active;
    auto tr = detail::make_traversal(nodes, nodes, act, act, cull, leaf_step());
    return detail::run_parallel(tr, {0, 0, true}, locals);
  }

  // traverse()'s walk from the front: first the self tests the walk from the root makes, a level
  // at a time (bit 0 of front_live[n]: the self test of n runs, its parent's did and was not
  // culled; bit 1: n is internal and not culled, so the pairs of its children are traversed),
  // then the front of every internal node, from its children pair on the first call.
  detail::TraversalCounters traverse_front(Rule mode, PairLocals& locals) {
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

  [[nodiscard]] detail::FeatureContext ccd_context() const {
    return detail::ccd_context(topo, v0, v1, opt, links);
  }

  using NarrowLocals = tbb::enumerable_thread_specific<NarrowBuffer>;

  // The feature pairs of `pairs` and of the orphans that collide (ctx's boxes are up to date).
  // With `near`, also flags the pairs whose faces are at most opt.reuse_distance apart at t1.
  void narrow(const detail::FeatureContext& ctx, const detail::PairList& pairs, DetectResult& res,
              std::vector<std::uint8_t>* near = nullptr) {
    NarrowLocals locals;
    narrow_pairs(ctx, pairs, locals, near);
    narrow_orphans(ctx, locals);
    res.stats.triangle_pairs = 0;
    gather(locals, res);
    finish(res);
  }

  // The feature pairs of the triangle pairs `pairs` that collide, into `locals`.
  void narrow_pairs(const detail::FeatureContext& ctx, const detail::PairList& pairs,
                    NarrowLocals& locals, std::vector<std::uint8_t>* near = nullptr) const {
    const bool wide = box_reach() > opt.thickness;
    if (near != nullptr) near->assign(pairs.size(), 0);
    const auto& faces = topo.faces();
    auto kvf = [&](int v, int f, const Face& t, NarrowBuffer& out) {
      ctx.queue_vf(v, f, t, out.batch, out.c, out.vf);
    };
    auto kee = [&](int a, int b, const Edge& ea, const Edge& eb, NarrowBuffer& out) {
      ctx.queue_ee(a, b, ea, eb, out.batch, out.c, out.ee);
    };
    // The pair loop waits on memory: a triangle pair's records and box blocks sit at scattered
    // places. Fetch them kFar pairs ahead (a record is one cache line, a block three), within
    // a piece of the list.
    constexpr std::size_t kFar = 16, kPiece = 1024;
    const auto fetch_face = [&](int f) {
      detail::prefetch(&owner.record(f));
      const auto* block = reinterpret_cast<const char*>(&ctx.face_boxes[f]);
      for (int line = 0; line < 3; ++line)
        detail::prefetch(block + 64 * line);
    };
    // Without the whole-triangle bound (faces_apart_filter), pair i of the list, faces f and g.
    const auto one = [&](std::size_t i, int f, int g, NarrowBuffer& out) {
      if (near != nullptr) {
        (*near)[i] =
            !(detail::triangle_triangle_bound(detail::corners(v1, faces[f]),
                                              detail::corners(v1, faces[g])) > opt.reuse_distance);
      }
      // Widened leaf boxes: no feature pair of faces whose own boxes miss.
      if (wide && !ctx.face_boxes[f].face_overlaps(ctx.face_boxes[g])) return;
      ++out.c.triangle_pairs;
      triangle_pair(ctx, f, g, out, kvf, kee);
    };
    // With it, pairs [k0, k1) of a piece: the box test and the queueing of the
    // pairs past it, the whole-triangle filter on them at once, then their feature pairs, in
    // list order.
    const auto batch = [&](std::size_t first, std::span<const detail::FacePair> piece,
                           std::size_t k0, std::size_t k1, NarrowBuffer& out) {
      detail::FacesApartBatch& fb = out.faces;
      detail::FaceBoundBatch& nb = out.near;
      for (std::size_t k = k0; k < k1; ++k) {
        if (k + kFar < piece.size()) {
          fetch_face(piece[k + kFar].first);
          fetch_face(piece[k + kFar].second);
        }
        const auto [f, g] = piece[k];
        fb.slot[k - k0] = nb.slot[k - k0] = -1;
        if (wide && !ctx.face_boxes[f].face_overlaps(ctx.face_boxes[g])) {
          if (near != nullptr) nb.slot[k - k0] = nb.push(ctx.v1, faces[f], ctx.v1, faces[g]);
          continue;
        }
        fb.slot[k - k0] = fb.push(ctx.v0, ctx.v1, faces[f], ctx.v0, ctx.v1, faces[g]);
      }
      if (nb.pairs.size > 0) {
        nb.run();
        for (std::size_t k = k0; k < k1; ++k) {
          const int s = nb.slot[k - k0];
          if (s >= 0) (*near)[first + k] = !(nb.bound[s] > opt.reuse_distance);
        }
      }
      fb.run(ctx.ccd.thickness);
      for (std::size_t k = k0; k < k1; ++k) {
        const int s = fb.slot[k - k0];
        if (s < 0) continue;
        ++out.c.triangle_pairs;
        if (near != nullptr) (*near)[first + k] = !(fb.bound_t1[s] > opt.reuse_distance);
        if (fb.apart[s]) {
          ++out.c.faces_apart;
          continue;
        }
        triangle_pair(ctx, piece[k].first, piece[k].second, out, kvf, kee);
      }
    };
    const bool batched = ctx.faces_apart_filter();
    constexpr std::size_t kBatch = detail::FacesApartBatch::kCapacity;
    const std::vector<detail::PairList::Piece> pieces = pairs.pieces(kPiece);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pieces.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        NarrowBuffer& out = locals.local();
                        for (std::size_t p = r.begin(); p != r.end(); ++p) {
                          const std::span<const detail::FacePair> piece = pieces[p].pairs;
                          if (batched) {
                            for (std::size_t k0 = 0; k0 < piece.size(); k0 += kBatch) {
                              batch(pieces[p].first, piece, k0, std::min(piece.size(), k0 + kBatch),
                                    out);
                            }
                            continue;
                          }
                          for (std::size_t k = 0; k < piece.size(); ++k) {
                            if (k + kFar < piece.size()) {
                              fetch_face(piece[k + kFar].first);
                              fetch_face(piece[k + kFar].second);
                            }
                            one(pieces[p].first + k, piece[k].first, piece[k].second, out);
                          }
                        }
                      });
    for (auto& l : locals)  // at most one partial batch of each kind per thread
      ctx.flush(l.batch, l.c, l.vf, l.ee);
  }

  // The orphan feature pairs that collide, into `locals`.
  void narrow_orphans(const detail::FeatureContext& ctx, NarrowLocals& locals) const {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, orphans.vf.size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        NarrowBuffer& out = locals.local();
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          const auto [v, f] = orphans.vf[i];
                          if (!vf_in_scope(v, f)) continue;
                          if (!detail::overlap(ctx.vertex_box(v), ctx.face_box(f))) continue;
                          ctx.kernel_vf(v, f, out.c, out.vf);
                        }
                      });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, orphans.ee.size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        NarrowBuffer& out = locals.local();
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          const auto [ea, eb] = orphans.ee[i];
                          if (!ee_in_scope(ea, eb)) continue;
                          if (!detail::overlap(ctx.edge_box(ea), ctx.edge_box(eb))) continue;
                          ctx.kernel_ee(ea, eb, out.c, out.ee);
                        }
                      });
  }

  // Adds the buffers' counters and collisions to `res` (left unsorted).
  static void gather(const NarrowLocals& locals, DetectResult& res) {
    DetectStats& st = res.stats;
    for (const auto& l : locals) {
      l.c.add_to(st);
      st.triangle_pairs += l.c.triangle_pairs;
      res.vf.insert(res.vf.end(), l.vf.begin(), l.vf.end());
      res.ee.insert(res.ee.end(), l.ee.begin(), l.ee.end());
    }
  }

  // Sorts the collisions and counts them, and the orphans every detection checks.
  void finish(DetectResult& res) const {
    DetectStats& st = res.stats;
    st.vf_orphans = orphans.vf.size();
    st.ee_orphans = orphans.ee.size();
    std::sort(res.vf.begin(), res.vf.end(), detail::vf_less);
    std::sort(res.ee.begin(), res.ee.end(), detail::ee_less);
    st.vf_collisions = res.vf.size();
    st.ee_collisions = res.ee.size();
  }

  // Tests the feature pairs of a non-adjacent triangle pair whose representative pair it is.
  // Needs the context's precomputed boxes and face blocks (`boxes` keeps both).
  template <class Out, class KernelVf, class KernelEe>
  void triangle_pair(const detail::FeatureContext& ctx, int f, int g, Out& out, KernelVf&& kvf,
                     KernelEe&& kee) const {
    detail::owned_feature_pairs(
        owner, detail::StepFaceBoxes{ctx}, f, g,
        [&](int v, int face, const Face& t) {
          if (vf_in_scope(v, face)) kvf(v, face, t, out);
        },
        [&](int e1, int e2, const Edge& a, const Edge& b) {
          if (ee_in_scope(e1, e2)) kee(e1, e2, a, b, out);
        });
  }

  // Boxes and cones for the current options, where vertices moved since the last refit (all of
  // it when the refit options changed).
  void refit(DetectStats& st) {
    const auto t = Clock::now();
    RefitOptions ro;
    ro.thickness = box_reach();
    ro.cones = cones_used(rule());
    ro.policy = opt.policy;
    ro.optimal_cones = opt.research.optimal_cones;
    // The unsound rules are measured on every node.
    if (rule() == Rule::Sound) ro.cone_min_triangles = opt.cull_min_triangles;
    bvh.refit_moved(v0, v1, ro, step.changed_since(bvh_call));
    bvh_call = step.call();
    st.time_refit = seconds_since(t);
    st.internal_nodes = bvh.num_internal();
    st.connected_internal_nodes = bvh.num_connected_internal();
    st.disk_internal_nodes = bvh.num_disk_internal();
  }

  // detect_each's walk of each configuration's rule over the nodes: refits to its cones (the
  // detector's options become configs[k], built as `build`), counts the rule's tests into
  // out[k].stats, and sets bit k of the result's entry n when the self test of internal node n
  // runs under configs[k], so that the pair traversal of n's children does.
  std::vector<std::uint64_t> kept_nodes(std::span<const DetectOptions> configs, BvhBuild build,
                                        std::vector<DetectResult>& out) {
    const auto& nodes = bvh.nodes();
    std::vector<std::uint64_t> keep(nodes.size(), 0);
    std::vector<int> stack;
    for (std::size_t k = 0; k < configs.size(); ++k) {
      opt = configs[k];
      opt.build = build;
      DetectStats& st = out[k].stats;
      refit(st);
      const Rule mode = rule();
      detail::TraversalCounters c;
      if (!nodes.empty()) stack.assign(1, 0);
      while (!stack.empty()) {
        const int i = stack.back();
        stack.pop_back();
        if (nodes[i].is_leaf()) continue;
        if (culls(mode, i, c)) {
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
  static void add_shared(const DetectResult& from, DetectResult& to) {
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

  // SelfDetector::detect_each. The self traversal without culling is the union, over the
  // internal nodes n, of the pair traversals of n's two children: every leaf pair below n whose
  // leaves lie on either side of the split. A culling rule removes exactly the pair traversals
  // of the nodes it culls and of their descendants. So each configuration walks its rule over
  // the nodes (refit to its cones), which marks the nodes whose pair traversal it keeps; the
  // nodes are grouped by the set of configurations that keep them; and each group's pair
  // traversals and narrow phase run once, their counters and collisions going to every
  // configuration of its set.
  std::vector<DetectResult> detect_each(detail::PointsIn p0, detail::PointsIn p1,
                                        std::span<const DetectOptions> configs) {
    constexpr std::size_t kMaxConfigs = 64;
    if (configs.size() > kMaxConfigs) {
      throw InputError(
          fmt::format("detect_each: {} configurations, at most {}", configs.size(), kMaxConfigs));
    }
    if (restricted) throw InputError("detect_each: clear the active restriction first");
    // Everything but the culling and the cones must match: boxes, kernels and links are shared.
    auto shared_part = [](DetectOptions o) {
      o.policy = {};
      o.culling = {};
      o.build = {};
      o.cull_min_triangles = 0;
      o.research.unsound_culling = {};
      o.research.optimal_cones = false;
      return o;
    };
    for (std::size_t k = 0; k < configs.size(); ++k) {
      const DetectOptions& c = configs[k];
      check_options(c);
      check_same_build(opt.build, c.build, fmt::format("detect_each: configuration {}", k));
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
    std::vector<DetectResult> out(configs.size());
    if (configs.empty()) return out;
    // The caller's options come back however this ends.
    struct Restore {
      Impl& im;
      DetectOptions saved;
      ~Restore() {
        im.opt = std::move(saved);
        im.links_current = false;
      }
    } restore{*this, opt};
    reuse.valid = false;
    step.update(p0, p1, topo.num_vertices(), "positions at t0", "positions at t1");
    opt = configs[0];
    opt.build = restore.saved.build;
    links = detail::sorted_links(opt.linked_vertices, topo.num_vertices());
    links_current = true;

    const std::vector<std::uint64_t> keep = kept_nodes(configs, restore.saved.build, out);
    const auto& nodes = bvh.nodes();

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
    auto leaf = [np = nodes.data(), pp = bvh.prim_ids().data(), pf = bvh.prim_faces().data()](
                    int a, int b, Local& out) {
      GroupPairs& gp = out.groups[out.g];
      const int ia = np[a].first, ib = np[b].first;
      if (faces_touch(pf[ia], pf[ib])) {
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
      const int big = std::max(64, topo.num_faces() / 64);
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
    detail::FeatureContext ctx = ccd_context();
    boxes.update(ctx, step);
    std::vector<DetectResult> found(ng);
    for (std::size_t g = 0; g < ng; ++g) {
      NarrowLocals narrow_locals;
      for (Local& l : locals) {
        GroupPairs& gp = l.groups[g];
        found[g].stats.box_tests += gp.box_tests;
        found[g].stats.adjacent_pairs += gp.adjacent;
        detail::PairList list;
        list.add(gp.pairs);
        narrow_pairs(ctx, list, narrow_locals);
      }
      gather(narrow_locals, found[g]);
    }
    DetectResult orphan_hits;
    {
      NarrowLocals narrow_locals;
      narrow_orphans(ctx, narrow_locals);
      gather(narrow_locals, orphan_hits);
    }
    for (std::size_t k = 0; k < configs.size(); ++k) {
      for (std::size_t g = 0; g < ng; ++g) {
        if ((sets[g] >> k) & 1U) add_shared(found[g], out[k]);
      }
      add_shared(orphan_hits, out[k]);
      finish(out[k]);
    }
    return out;
  }

  DetectResult detect(detail::PointsIn p0, detail::PointsIn p1) {
    step.update(p0, p1, topo.num_vertices(), "positions at t0", "positions at t1");
    update_links();
    DetectResult res;
    DetectStats& st = res.stats;
    refit(st);
    auto t = Clock::now();
    const detail::PairList pairs =
        traverse(rule(), st, pair_locals, opt.reuse_front && !restricted);
    st.time_traverse = seconds_since(t);
    t = Clock::now();
    detail::FeatureContext ctx = ccd_context();
    boxes.update(ctx, step);
    const bool keep = keeps() && !restricted;
    std::vector<std::uint8_t> near;
    narrow(ctx, pairs, res, keep ? &near : nullptr);
    st.time_narrow = seconds_since(t);
    if (keep) {
      reuse.x1 = v1;
      reuse.pairs.clear();
      pairs.for_each([&](std::size_t i, const detail::FacePair& p) {
        if (near[i] != 0) reuse.pairs.push_back(p);
      });
      reuse.valid = true;
    }

    if (opt.research.verify && rule() != Rule::None) {
      DetectResult ref;
      PairLocals all_locals;  // `pairs` is still in use
      const detail::PairList all = traverse(Rule::None, ref.stats, all_locals);
      narrow(ctx, all, ref);
      research::Verification& ver = res.verification;
      ver.ran = true;
      ver.unculled_triangle_pairs = all.size();
      std::set_difference(ref.vf.begin(), ref.vf.end(), res.vf.begin(), res.vf.end(),
                          std::back_inserter(ver.missed_vf), detail::vf_less);
      std::set_difference(ref.ee.begin(), ref.ee.end(), res.ee.begin(), res.ee.end(),
                          std::back_inserter(ver.missed_ee), detail::ee_less);
    }
    return res;
  }

  ProximityResult proximity(detail::PointsIn p, double h) {
    if (!(h >= 0) || !std::isfinite(h)) {
      throw InputError(fmt::format("proximity distance must be finite and >= 0, got {}", h));
    }
    step.update_static(p, topo.num_vertices(), "positions");
    update_links();
    RefitOptions ro;
    ro.thickness = h;
    ro.cones = false;  // cones carry no distance information (docs/algorithms.md 1.1)
    bvh.refit(v0, ro);
    bvh_call = 0;
    detail::FeatureContext ctx = detail::proximity_context(topo, v0, h, links);
    boxes.update(ctx, step);
    struct Buffer {
      std::vector<ProximityResult::VertexFace> vf;
      std::vector<ProximityResult::EdgeEdge> ee;
      detail::FaceBoundBatch bounds;  // a piece's triangle pairs past the box test
    };
    tbb::enumerable_thread_specific<Buffer> locals;
    // Linked pairs are left out as detect() leaves them out (DetectOptions::linked_vertices).
    auto kvf = [&](int v, int f, const Face& t, Buffer& out) {
      if (!ctx.links.empty() && ctx.vf_linked(v, f)) return;
      const double d = detail::point_triangle_within(v0[v], v0[t[0]], v0[t[1]], v0[t[2]], h);
      if (d <= h) out.vf.push_back({v, f, d});
    };
    auto kee = [&](int a, int b, const Edge& ea, const Edge& eb, Buffer& out) {
      if (!ctx.links.empty() && ctx.ee_linked(a, b)) return;
      const double d = detail::edge_edge_within(v0[ea[0]], v0[ea[1]], v0[eb[0]], v0[eb[1]], h);
      if (d <= h) out.ee.push_back({a, b, d});
    };
    // A piece at a time: the box test, the whole triangles' bound of the pairs past it at once
    // (no feature pair is closer), then the feature pairs of those within h, in list order.
    auto test_pairs = [&](const detail::PairList& pairs) {
      const std::vector<detail::PairList::Piece> pieces =
          pairs.pieces(detail::FaceBoundBatch::kCapacity);
      const auto& faces = topo.faces();
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pieces.size(), 1),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          Buffer& out = locals.local();
                          detail::FaceBoundBatch& nb = out.bounds;
                          for (std::size_t p = r.begin(); p != r.end(); ++p) {
                            const std::span<const detail::FacePair> piece = pieces[p].pairs;
                            for (std::size_t k = 0; k < piece.size(); ++k) {
                              const auto [f, g] = piece[k];
                              nb.slot[k] = detail::overlap(ctx.fboxes[f], ctx.fboxes[g])
                                               ? nb.push(v0, faces[f], v0, faces[g])
                                               : -1;
                            }
                            nb.run();
                            for (std::size_t k = 0; k < piece.size(); ++k) {
                              const int s = nb.slot[k];
                              if (s < 0 || nb.bound[s] > h) continue;
                              triangle_pair(ctx, piece[k].first, piece[k].second, out, kvf, kee);
                            }
                          }
                        });
    };
    DetectStats st;
    std::size_t reused = 0;
    if (reusable(h)) {
      // The kept pairs hold every pair of features on vertices still at their t1 positions (the
      // widened boxes held these positions and more); a traversal restricted to the moved
      // vertices finds the rest. The two scopes split the feature pairs exactly.
      struct Unrestrict {
        Impl& im;
        ~Unrestrict() { im.restricted = im.outside = false; }
      } unrestrict{*this};
      outside = true;
      test_pairs(detail::PairList(reuse.pairs));
      reused = reuse.pairs.size();
      outside = false;
      test_pairs(traverse(Rule::None, st, pair_locals));
    } else {
      test_pairs(traverse(Rule::None, st, pair_locals));
    }
    Buffer& out = locals.local();
    for (const auto& [v, f] : orphans.vf) {
      if (vf_in_scope(v, f) && detail::overlap(ctx.vertex_box(v), ctx.face_box(f))) {
        kvf(v, f, topo.faces()[f], out);
      }
    }
    for (const auto& [a, b] : orphans.ee) {
      if (ee_in_scope(a, b) && detail::overlap(ctx.edge_box(a), ctx.edge_box(b))) {
        kee(a, b, topo.edges()[a], topo.edges()[b], out);
      }
    }
    ProximityResult res;
    res.reused_pairs = reused;
    for (const auto& l : locals) {
      res.vf.insert(res.vf.end(), l.vf.begin(), l.vf.end());
      res.ee.insert(res.ee.end(), l.ee.begin(), l.ee.end());
    }
    std::sort(res.vf.begin(), res.vf.end(), [](const auto& a, const auto& b) {
      return std::pair(a.vertex, a.face) < std::pair(b.vertex, b.face);
    });
    std::sort(res.ee.begin(), res.ee.end(), [](const auto& a, const auto& b) {
      return std::pair(a.edge_a, a.edge_b) < std::pair(b.edge_a, b.edge_b);
    });
    return res;
  }

  // Whether proximity(v0, h) can use the kept pairs: then the active restriction is set to the
  // vertices that moved since (few, or the traversal is cheaper). `reuse.valid` implies keeps():
  // only detect() sets it, and set_options() clears it.
  bool reusable(double h) {
    if (!reuse.valid || restricted || h > opt.reuse_distance) return false;
    const int nv = topo.num_vertices();
    std::vector<int> moved;
    for (int i = 0; i < nv; ++i) {
      if (v0[i] != reuse.x1[i]) moved.push_back(i);
    }
    if (4 * moved.size() > static_cast<std::size_t>(nv)) return false;
    set_active_vertices(moved);
    return true;
  }

  void set_active(std::span<const int> active_faces) {
    const int nf = topo.num_faces();
    face_active.assign(nf, 0);
    vertex_active.assign(topo.num_vertices(), 0);
    edge_active.assign(topo.num_edges(), 0);
    for (int f : active_faces) {
      if (f < 0 || f >= nf) {
        throw InputError(fmt::format("active face {} is out of range [0, {})", f, nf));
      }
      face_active[f] = 1;
      for (int v : topo.faces()[f])
        vertex_active[v] = 1;
      for (int e : topo.face_edges(f))
        edge_active[e] = 1;
    }
    // A face touching an active vertex can be the representative of an in-scope pair.
    std::vector<std::uint8_t> touch(nf, 0);
    for (int f = 0; f < nf; ++f) {
      for (int v : topo.faces()[f])
        touch[f] |= vertex_active[v];
    }
    set_nodes(touch);
  }

  // Scope by vertices: a VF pair when its vertex or a vertex of its face is active, an EE pair
  // when an endpoint is active. A face then counts as active when it has an active vertex, and
  // only such faces can represent an in-scope pair.
  void set_active_vertices(std::span<const int> active_vertices) {
    const int nv = topo.num_vertices();
    vertex_active.assign(nv, 0);
    for (int v : active_vertices) {
      if (v < 0 || v >= nv) {
        throw InputError(fmt::format("active vertex {} is out of range [0, {})", v, nv));
      }
      vertex_active[v] = 1;
    }
    face_active = topo.faces_touching(vertex_active);
    edge_active = topo.edges_touching(vertex_active);
    set_nodes(face_active);
  }

  // Nodes holding a face that can represent an in-scope pair.
  void set_nodes(const std::vector<std::uint8_t>& touch) {
    node_active = bvh.nodes_holding(touch);
    restricted = true;
  }
};

namespace {
// SelfDetector::rebuild for either input form.
template <class Impl>
void rebuild_detector(Impl& im, detail::PointsIn reference) {
  std::vector<Eigen::Vector3d> ref;
  detail::to_points(reference, im.topo.num_vertices(), "reference shape", ref);
  im.bvh = Bvh(im.topo, ref, im.opt.build);
  im.bvh_call = 0;
  im.restricted = false;  // its node flags belonged to the old tree
  im.front.clear();       // and so did the front's node pairs
}
}  // namespace

SelfDetector::SelfDetector(std::vector<Face> faces, int num_vertices, const Positions& reference,
                           const DetectOptions& options)
    : impl_(std::make_unique<Impl>(std::move(faces), num_vertices, reference, options)) {}
SelfDetector::SelfDetector(std::vector<Face> faces, int num_vertices,
                           std::span<const Eigen::Vector3d> reference, const DetectOptions& options)
    : impl_(std::make_unique<Impl>(std::move(faces), num_vertices, reference, options)) {}
SelfDetector::SelfDetector(const Eigen::Ref<const Eigen::MatrixX3i>& faces,
                           const Positions& reference, const DetectOptions& options)
    : impl_(std::make_unique<Impl>(to_faces(faces), static_cast<int>(reference.rows()), reference,
                                   options)) {}
SelfDetector::~SelfDetector() = default;
SelfDetector::SelfDetector(SelfDetector&&) noexcept = default;
SelfDetector& SelfDetector::operator=(SelfDetector&&) noexcept = default;

DetectResult SelfDetector::detect(const Positions& v_t0, const Positions& v_t1) {
  return impl_->detect(v_t0, v_t1);
}
DetectResult SelfDetector::detect(std::span<const Eigen::Vector3d> v_t0,
                                  std::span<const Eigen::Vector3d> v_t1) {
  return impl_->detect(v_t0, v_t1);
}
std::vector<DetectResult> SelfDetector::detect_each(const Positions& v_t0, const Positions& v_t1,
                                                    std::span<const DetectOptions> configs) {
  return impl_->detect_each(v_t0, v_t1, configs);
}
std::vector<DetectResult> SelfDetector::detect_each(std::span<const Eigen::Vector3d> v_t0,
                                                    std::span<const Eigen::Vector3d> v_t1,
                                                    std::span<const DetectOptions> configs) {
  return impl_->detect_each(v_t0, v_t1, configs);
}
ProximityResult SelfDetector::proximity(const Positions& v, double h) {
  return impl_->proximity(v, h);
}
ProximityResult SelfDetector::proximity(std::span<const Eigen::Vector3d> v, double h) {
  return impl_->proximity(v, h);
}
void SelfDetector::set_active_faces(std::span<const int> faces) {
  impl_->set_active(faces);
}
void SelfDetector::set_active_vertices(std::span<const int> vertices) {
  impl_->set_active_vertices(vertices);
}
void SelfDetector::clear_active() {
  impl_->restricted = false;
}
void SelfDetector::rebuild(const Positions& reference) {
  rebuild_detector(*impl_, reference);
}
void SelfDetector::rebuild(std::span<const Eigen::Vector3d> reference) {
  rebuild_detector(*impl_, reference);
}
const DetectOptions& SelfDetector::options() const {
  return impl_->opt;
}
void SelfDetector::set_options(const DetectOptions& options) {
  check_options(options);
  check_same_build(impl_->opt.build, options.build, "set_options");
  impl_->opt = options;
  impl_->links_current = false;
  impl_->reuse.valid = false;
  if (!options.reuse_front) impl_->front.clear();
}
const Topology& SelfDetector::topology() const {
  return impl_->topo;
}
const Bvh& SelfDetector::bvh() const {
  return impl_->bvh;
}

}  // namespace clothcd
