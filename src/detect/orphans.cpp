#include "orphans.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "narrow.hpp"

namespace clothcd::detail {

namespace {

// The orphans found at vertex v (each vertex-sharing face pair is visited at its smallest shared
// vertex), appended unsorted and possibly repeated.
void orphans_at(const Topology& topo, int v, Orphans& o) {
  const auto& faces = topo.faces();
  const auto vf = topo.vertex_faces(v);
  for (std::size_t i = 0; i < vf.size(); ++i) {
    for (std::size_t j = i + 1; j < vf.size(); ++j) {
      const int f = vf[i], g = vf[j];
      const Face &tf = faces[f], &tg = faces[g];
      // Visit each vertex-sharing pair once: at its smallest shared vertex.
      int smallest = -1;
      for (int x : tf) {
        if ((x == tg[0] || x == tg[1] || x == tg[2]) && (smallest < 0 || x < smallest)) {
          smallest = x;
        }
      }
      if (smallest != v) continue;
      auto vf_candidate = [&](int p, int face) {
        const Face& t = faces[face];
        if (p == t[0] || p == t[1] || p == t[2]) return;
        if (vf_representative(topo, p, face) < 0) o.vf.emplace_back(p, face);
      };
      for (int p : tf)
        vf_candidate(p, g);
      for (int p : tg)
        vf_candidate(p, f);
      for (int ea : topo.face_edges(f)) {
        for (int eb : topo.face_edges(g)) {
          const Edge &a = topo.edges()[ea], &b = topo.edges()[eb];
          if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) continue;
          const int e1 = std::min(ea, eb), e2 = std::max(ea, eb);
          if (ee_representative(topo, e1, e2).first < 0) o.ee.emplace_back(e1, e2);
        }
      }
    }
  }
}

}  // namespace

Orphans find_orphans(const Topology& topo) {
  // Vertices are independent: per-thread lists, merged, then sorted and made unique as before.
  tbb::enumerable_thread_specific<Orphans> locals;
  tbb::parallel_for(tbb::blocked_range<int>(0, topo.num_vertices(), 1024),
                    [&](const tbb::blocked_range<int>& r) {
                      Orphans& l = locals.local();
                      for (int v = r.begin(); v != r.end(); ++v)
                        orphans_at(topo, v, l);
                    });
  Orphans o;
  for (const Orphans& l : locals) {
    o.vf.insert(o.vf.end(), l.vf.begin(), l.vf.end());
    o.ee.insert(o.ee.end(), l.ee.begin(), l.ee.end());
  }
  std::sort(o.vf.begin(), o.vf.end());
  o.vf.erase(std::unique(o.vf.begin(), o.vf.end()), o.vf.end());
  std::sort(o.ee.begin(), o.ee.end());
  o.ee.erase(std::unique(o.ee.begin(), o.ee.end()), o.ee.end());
  return o;
}

}  // namespace clothcd::detail
