// Inter-object detection between two meshes (garment against body): pair traversal of the two
// BVHs, then each VF / EE feature pair tested once, at the pair of the features' first faces.

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>

#include "clothcd/detect/detector.hpp"
#include "clothcd/detect/oracle.hpp"
#include "narrow.hpp"
#include "options.hpp"
#include "positions.hpp"
#include "traversal.hpp"

namespace clothcd {
namespace {

using Clock = std::chrono::steady_clock;

struct Side {
  const Topology* topo;
  std::span<const Eigen::Vector3d> v0, v1;
};

struct Buffer {
  detail::FeatureCounters c;
  std::vector<VertexFaceCollision> ab, ba;
  std::vector<EdgeEdgeCollision> ee;
};

struct PairKernels {
  Side a, b;
  double margin;
  bool np;
  CcdOptions ccd;

  detail::Box vbox(const Side& s, int v) const {
    return detail::swept_box({&s.v0[v], &s.v1[v]}, margin);
  }
  detail::Box fbox(const Side& s, int f) const {
    const Face& t = s.topo->faces()[f];
    return detail::swept_box(
        {&s.v0[t[0]], &s.v0[t[1]], &s.v0[t[2]], &s.v1[t[0]], &s.v1[t[1]], &s.v1[t[2]]}, margin);
  }
  detail::Box ebox(const Side& s, int e) const {
    const Edge& d = s.topo->edges()[e];
    return detail::swept_box({&s.v0[d[0]], &s.v0[d[1]], &s.v1[d[0]], &s.v1[d[1]]}, margin);
  }
  void vf(const Side& sv, int v, const Side& sf, int f, Buffer& out,
          std::vector<VertexFaceCollision>& dst) const {
    ++out.c.vf_tests;
    const Face& t = sf.topo->faces()[f];
    const VertexFaceQuery q{sv.v0[v], sf.v0[t[0]], sf.v0[t[1]], sf.v0[t[2]],
                            sv.v1[v], sf.v1[t[0]], sf.v1[t[1]], sf.v1[t[2]]};
    if (np && ccd.thickness == 0 && np_filter_culls(q)) {
      ++out.c.vf_np;
      return;
    }
    const CcdResult r = vertex_face_ccd(q, ccd);
    if (r.hit) dst.push_back({v, f, t, r.toi});
  }
  void ee(int ea, int eb, Buffer& out) const {
    ++out.c.ee_tests;
    const Edge& x = a.topo->edges()[ea];
    const Edge& y = b.topo->edges()[eb];
    const EdgeEdgeQuery q{a.v0[x[0]], a.v0[x[1]], b.v0[y[0]], b.v0[y[1]],
                          a.v1[x[0]], a.v1[x[1]], b.v1[y[0]], b.v1[y[1]]};
    if (np && ccd.thickness == 0 && np_filter_culls(q)) {
      ++out.c.ee_np;
      return;
    }
    const CcdResult r = edge_edge_ccd(q, ccd);
    if (r.hit) out.ee.push_back({ea, eb, x, y, r.toi});
  }
  // Feature pairs of faces (fa, fb) whose first faces they are; `all` skips that rule (oracle).
  void face_pair(int fa, int fb, Buffer& out, bool all) const {
    const detail::Box ba = fbox(a, fa), bb = fbox(b, fb);
    for (int v : a.topo->faces()[fa]) {
      if ((all || a.topo->vertex_faces(v)[0] == fa) && detail::overlap(vbox(a, v), bb)) {
        vf(a, v, b, fb, out, out.ab);
      }
    }
    for (int v : b.topo->faces()[fb]) {
      if ((all || b.topo->vertex_faces(v)[0] == fb) && detail::overlap(vbox(b, v), ba)) {
        vf(b, v, a, fa, out, out.ba);
      }
    }
    for (int ea : a.topo->face_edges(fa)) {
      if (!all && a.topo->edge_faces(ea)[0] != fa) continue;
      const detail::Box xa = ebox(a, ea);
      for (int eb : b.topo->face_edges(fb)) {
        if (!all && b.topo->edge_faces(eb)[0] != fb) continue;
        if (detail::overlap(xa, ebox(b, eb))) ee(ea, eb, out);
      }
    }
  }
};

template <class T, class Less>
void sort_unique(std::vector<T>& v, Less less) {
  std::sort(v.begin(), v.end(), less);
  v.erase(std::unique(v.begin(), v.end(),
                      [&](const T& x, const T& y) { return !less(x, y) && !less(y, x); }),
          v.end());
}

PairDetectResult collect(tbb::enumerable_thread_specific<Buffer>& locals, bool dedupe) {
  PairDetectResult res;
  for (const auto& l : locals) {
    res.stats.vf_tests += l.c.vf_tests;
    res.stats.ee_tests += l.c.ee_tests;
    res.stats.vf_np_culled += l.c.vf_np;
    res.stats.ee_np_culled += l.c.ee_np;
    res.vf_a_on_b.insert(res.vf_a_on_b.end(), l.ab.begin(), l.ab.end());
    res.vf_b_on_a.insert(res.vf_b_on_a.end(), l.ba.begin(), l.ba.end());
    res.ee.insert(res.ee.end(), l.ee.begin(), l.ee.end());
  }
  if (dedupe) {
    sort_unique(res.vf_a_on_b, detail::vf_less);
    sort_unique(res.vf_b_on_a, detail::vf_less);
    sort_unique(res.ee, detail::ee_less);
  } else {
    std::sort(res.vf_a_on_b.begin(), res.vf_a_on_b.end(), detail::vf_less);
    std::sort(res.vf_b_on_a.begin(), res.vf_b_on_a.end(), detail::vf_less);
    std::sort(res.ee.begin(), res.ee.end(), detail::ee_less);
  }
  res.stats.vf_collisions = res.vf_a_on_b.size() + res.vf_b_on_a.size();
  res.stats.ee_collisions = res.ee.size();
  return res;
}

}  // namespace

struct PairDetector::Impl {
  Topology ta, tb;
  DetectOptions opt;
  Bvh ba, bb;
  std::vector<Eigen::Vector3d> a0, a1, b0, b1;

  Impl(std::vector<Face> fa, int na, const Positions& ra, std::vector<Face> fb, int nb,
       const Positions& rb, const DetectOptions& o)
      : ta(std::move(fa), na), tb(std::move(fb), nb), opt(o) {
    detail::check_common_options(o);
    detail::to_points(ra, na, "reference shape A", a0);
    detail::to_points(rb, nb, "reference shape B", b0);
    ba = Bvh(ta, a0, o.build);
    bb = Bvh(tb, b0, o.build);
  }
};

PairDetector::PairDetector(std::vector<Face> faces_a, int num_vertices_a,
                           const Positions& reference_a, std::vector<Face> faces_b,
                           int num_vertices_b, const Positions& reference_b,
                           const DetectOptions& options)
    : impl_(std::make_unique<Impl>(std::move(faces_a), num_vertices_a, reference_a,
                                   std::move(faces_b), num_vertices_b, reference_b, options)) {}
PairDetector::~PairDetector() = default;
PairDetector::PairDetector(PairDetector&&) noexcept = default;
PairDetector& PairDetector::operator=(PairDetector&&) noexcept = default;

PairDetectResult PairDetector::detect(const Positions& a_t0, const Positions& a_t1,
                                      const Positions& b_t0, const Positions& b_t1) {
  Impl& m = *impl_;
  detail::to_points(a_t0, m.ta.num_vertices(), "mesh A at t0", m.a0);
  detail::to_points(a_t1, m.ta.num_vertices(), "mesh A at t1", m.a1);
  detail::to_points(b_t0, m.tb.num_vertices(), "mesh B at t0", m.b0);
  detail::to_points(b_t1, m.tb.num_vertices(), "mesh B at t1", m.b1);
  auto t = Clock::now();
  RefitOptions ro;
  ro.thickness = m.opt.thickness;
  ro.cones = false;  // no self-collision between two objects: cones cannot cull
  m.ba.refit(m.a0, m.a1, ro);
  m.bb.refit(m.b0, m.b1, ro);
  const double t_refit = std::chrono::duration<double>(Clock::now() - t).count();
  PairDetectResult res;
  if (m.ba.nodes().empty() || m.bb.nodes().empty()) return res;

  t = Clock::now();
  struct Pairs {
    std::vector<std::pair<int, int>> v;
  };
  const auto& pa = m.ba.prim_ids();
  const auto& pb = m.bb.prim_ids();
  const auto& na = m.ba.nodes();
  const auto& nb = m.bb.nodes();
  auto tr = detail::make_traversal(
      std::span<const BvhNode>(na), std::span<const BvhNode>(nb), {}, {},
      [](int, detail::TraversalCounters&) { return false; },
      [&](int x, int y, Pairs& out) { out.v.emplace_back(pa[na[x].first], pb[nb[y].first]); });
  tbb::enumerable_thread_specific<Pairs> plocals;
  const auto counters = detail::run_parallel(tr, {0, 0, false}, plocals);
  std::vector<std::pair<int, int>> pairs;
  for (const auto& l : plocals)
    pairs.insert(pairs.end(), l.v.begin(), l.v.end());
  const double t_trav = std::chrono::duration<double>(Clock::now() - t).count();

  t = Clock::now();
  const PairKernels k{{&m.ta, m.a0, m.a1},
                      {&m.tb, m.b0, m.b1},
                      0.5 * m.opt.thickness,
                      m.opt.np_filter,
                      CcdOptions{m.opt.thickness, m.opt.fast_path}};
  tbb::enumerable_thread_specific<Buffer> locals;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pairs.size(), 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      Buffer& out = locals.local();
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        k.face_pair(pairs[i].first, pairs[i].second, out, false);
                      }
                    });
  res = collect(locals, false);
  res.stats.time_refit = t_refit;
  res.stats.time_traverse = t_trav;
  res.stats.time_narrow = std::chrono::duration<double>(Clock::now() - t).count();
  res.stats.box_tests = counters.box_tests;
  res.stats.triangle_pairs = pairs.size();
  return res;
}

PairDetectResult brute_force_detect_pair(const Topology& a, const Positions& a_t0,
                                         const Positions& a_t1, const Topology& b,
                                         const Positions& b_t0, const Positions& b_t1,
                                         const DetectOptions& options) {
  std::vector<Eigen::Vector3d> a0, a1, b0, b1;
  detail::to_points(a_t0, a.num_vertices(), "mesh A at t0", a0);
  detail::to_points(a_t1, a.num_vertices(), "mesh A at t1", a1);
  detail::to_points(b_t0, b.num_vertices(), "mesh B at t0", b0);
  detail::to_points(b_t1, b.num_vertices(), "mesh B at t1", b1);
  const PairKernels k{{&a, a0, a1},
                      {&b, b0, b1},
                      0.5 * options.thickness,
                      options.np_filter,
                      CcdOptions{options.thickness, options.fast_path}};
  tbb::enumerable_thread_specific<Buffer> locals;
  // Every face pair with every feature: duplicates removed afterwards.
  tbb::parallel_for(0, a.num_faces(), [&](int fa) {
    Buffer& out = locals.local();
    for (int fb = 0; fb < b.num_faces(); ++fb)
      k.face_pair(fa, fb, out, true);
  });
  return collect(locals, true);
}

}  // namespace clothcd
