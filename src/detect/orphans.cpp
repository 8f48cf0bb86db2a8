#include "orphans.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "narrow.hpp"

namespace clothcd::detail {

namespace {

// One thread's finds, and a stamp per face and per edge: the feature whose candidates are being
// examined, so that each candidate is examined once per feature.
struct Scratch {
  Orphans found;
  std::vector<int> face_seen, edge_seen;
};

// VF orphans of vertex p: the faces g without p that touch every face of p (then no face of p
// can represent (p, g)). Such a g touches p's first face at one of its two other corners, so the
// faces at those corners are the only candidates. A vertex on no face has no VF pair to test.
void vf_orphans_of(const Topology& topo, int p, Scratch& s) {
  const auto& faces = topo.faces();
  const auto star = topo.vertex_faces(p);
  if (star.empty()) return;
  for (int x : faces[star[0]]) {
    if (x == p) continue;
    for (int g : topo.vertex_faces(x)) {
      if (s.face_seen[g] == p) continue;
      s.face_seen[g] = p;
      const Face& tg = faces[g];
      if (has_corner(tg, p)) continue;
      const bool orphan =
          std::all_of(star.begin(), star.end(), [&](int h) { return share_vertex(faces[h], tg); });
      if (orphan) s.found.vf.emplace_back(p, g);
    }
  }
}

// EE orphans (ea, eb) with ea < eb: edges sharing no vertex such that every face of ea touches
// every face of eb. Then eb's first face touches ea's first face h, at a corner of h, so eb is an
// edge of a face at one of h's corners: the only candidates.
void ee_orphans_of(const Topology& topo, int ea, Scratch& s) {
  const auto& faces = topo.faces();
  const auto& edges = topo.edges();
  const auto fa = topo.edge_faces(ea);
  const Edge& a = edges[ea];
  for (int x : faces[fa[0]]) {
    for (int g : topo.vertex_faces(x)) {
      for (int eb : topo.face_edges(g)) {
        if (eb <= ea || s.edge_seen[eb] == ea) continue;
        s.edge_seen[eb] = ea;
        const Edge& b = edges[eb];
        if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) continue;
        const auto fb = topo.edge_faces(eb);
        const bool orphan = std::all_of(fa.begin(), fa.end(), [&](int f) {
          return std::all_of(fb.begin(), fb.end(),
                             [&](int h) { return share_vertex(faces[f], faces[h]); });
        });
        if (orphan) s.found.ee.emplace_back(ea, eb);
      }
    }
  }
}

}  // namespace

Orphans find_orphans(const Topology& topo) {
  // Features are independent: per-thread lists, merged and sorted.
  tbb::enumerable_thread_specific<Scratch> locals([&] {
    Scratch s;
    s.face_seen.assign(topo.num_faces(), -1);
    s.edge_seen.assign(topo.num_edges(), -1);
    return s;
  });
  tbb::parallel_for(tbb::blocked_range<int>(0, topo.num_vertices(), 1024),
                    [&](const tbb::blocked_range<int>& r) {
                      Scratch& s = locals.local();
                      for (int v = r.begin(); v != r.end(); ++v)
                        vf_orphans_of(topo, v, s);
                    });
  tbb::parallel_for(tbb::blocked_range<int>(0, topo.num_edges(), 1024),
                    [&](const tbb::blocked_range<int>& r) {
                      Scratch& s = locals.local();
                      for (int e = r.begin(); e != r.end(); ++e)
                        ee_orphans_of(topo, e, s);
                    });
  Orphans o;
  for (const Scratch& l : locals) {
    o.vf.insert(o.vf.end(), l.found.vf.begin(), l.found.vf.end());
    o.ee.insert(o.ee.end(), l.found.ee.begin(), l.found.ee.end());
  }
  std::sort(o.vf.begin(), o.vf.end());
  std::sort(o.ee.begin(), o.ee.end());
  return o;
}

}  // namespace clothcd::detail
