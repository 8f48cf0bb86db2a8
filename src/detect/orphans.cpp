#include "orphans.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>

#include "narrow.hpp"

namespace clothcd::detail {

namespace {

// One thread's finds, and a stamp per face and per edge: the feature whose candidates are being
// examined, so that each candidate is examined once per feature; the apexes of an edge's faces.
struct Scratch {
  Orphans found;
  std::vector<int> face_seen, edge_seen, apexes;
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

// Index of corner x in t, or -1.
int corner_index(const Face& t, int x) {
  return x == t[0] ? 0 : x == t[1] ? 1 : x == t[2] ? 2 : -1;
}

// EE orphans (ea, eb) with ea < eb: edges sharing no vertex such that every face of ea touches
// every face of eb. A face g of eb then touches ea's first face, so g has one of its corners: the
// faces at those three corners are the only candidates for g. A face touches a face (a0, a1, w)
// of ea = (a0, a1) exactly when it holds a0, a1 or the apex w; so g touches all of ea's faces when
// it holds a0 or a1 or every apex. eb avoids a0 and a1: in a face holding a0 (a1) only the edge
// opposite it can be eb, and a face holding neither must hold every apex (rare: one face of ea,
// or apexes joined by an edge).
void ee_orphans_of(const Topology& topo, int ea, Scratch& s) {
  const auto& faces = topo.faces();
  const auto fa = topo.edge_faces(ea);
  const int a0 = topo.edges()[ea][0], a1 = topo.edges()[ea][1];
  s.apexes.clear();
  for (int f : fa) {
    for (int x : faces[f]) {
      if (x != a0 && x != a1) s.apexes.push_back(x);
    }
  }
  const auto has_apexes = [&](const Face& t) {
    return std::all_of(s.apexes.begin(), s.apexes.end(), [&](int w) { return has_corner(t, w); });
  };
  const auto touches_all_of_a = [&](const Face& t) {
    return has_corner(t, a0) || has_corner(t, a1) || has_apexes(t);
  };
  for (int x : faces[fa[0]]) {
    for (int g : topo.vertex_faces(x)) {
      const Face& tg = faces[g];
      const int i0 = corner_index(tg, a0), i1 = corner_index(tg, a1);
      if (i0 >= 0 && i1 >= 0) continue;  // a face of ea: every edge touches it
      // Bit k: edge k of g (corners k and k + 1) may be eb.
      unsigned edges = 0;
      if (i0 >= 0 || i1 >= 0) {
        edges = 1u << ((std::max(i0, i1) + 1) % 3);
      } else if (has_apexes(tg)) {
        edges = 7u;
      }
      for (; edges != 0; edges &= edges - 1) {
        const int eb = topo.face_edges(g)[std::countr_zero(edges)];
        if (eb <= ea || s.edge_seen[eb] == ea) continue;
        s.edge_seen[eb] = ea;
        const auto fb = topo.edge_faces(eb);
        if (std::all_of(fb.begin(), fb.end(), [&](int h) { return touches_all_of_a(faces[h]); }))
          s.found.ee.emplace_back(ea, eb);
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
