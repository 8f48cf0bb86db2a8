// Seam recovery: boundary vertex to another panel's boundary edge, via a uniform grid.
#include "clothcd/sim/sewing.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "clothcd/mesh/topology.hpp"

namespace clothcd::sim {

std::vector<Stitch> recover_stitches(const std::vector<Vec3>& x, const std::vector<Face>& faces,
                                     double max_distance) {
  const Topology topo(faces, static_cast<int>(x.size()));
  std::vector<int> panel(x.size(), -1);
  for (int f = 0; f < topo.num_faces(); ++f) {
    for (int v : faces[f])
      panel[v] = topo.face_component(f);
  }
  std::vector<int> boundary_edges;
  std::vector<bool> on_boundary(x.size(), false);
  for (int e = 0; e < topo.num_edges(); ++e) {
    if (topo.edge_faces(e).size() != 1) continue;
    boundary_edges.push_back(e);
    for (int v : topo.edges()[e])
      on_boundary[v] = true;
  }
  // Hash the edges' boxes into cells of size >= max_distance.
  const double cell = std::max(max_distance, 1e-6) * 4.0;
  auto key = [](long i, long j, long k) {
    return (i * 73856093L) ^ (j * 19349663L) ^ (k * 83492791L);
  };
  auto coord = [cell](double v) { return static_cast<long>(std::floor(v / cell)); };
  std::unordered_map<long, std::vector<int>> grid;
  for (int e : boundary_edges) {
    const Vec3& a = x[topo.edges()[e][0]];
    const Vec3& b = x[topo.edges()[e][1]];
    const Vec3 lo = a.cwiseMin(b).array() - max_distance;
    const Vec3 hi = a.cwiseMax(b).array() + max_distance;
    for (long i = coord(lo.x()); i <= coord(hi.x()); ++i) {
      for (long j = coord(lo.y()); j <= coord(hi.y()); ++j) {
        for (long k = coord(lo.z()); k <= coord(hi.z()); ++k)
          grid[key(i, j, k)].push_back(e);
      }
    }
  }
  std::vector<Stitch> out;
  for (int v = 0; v < static_cast<int>(x.size()); ++v) {
    if (!on_boundary[v]) continue;
    const Vec3& p = x[v];
    const auto it = grid.find(key(coord(p.x()), coord(p.y()), coord(p.z())));
    if (it == grid.end()) continue;
    double best = max_distance;
    Stitch st{-1, 0, 0, 0.0};
    for (int e : it->second) {
      const int a = topo.edges()[e][0], b = topo.edges()[e][1];
      if (panel[a] == panel[v]) continue;
      const Vec3 d = x[b] - x[a];
      const double len2 = d.squaredNorm();
      const double r = len2 > 0.0 ? std::clamp((p - x[a]).dot(d) / len2, 0.0, 1.0) : 0.0;
      const double dist = (p - (x[a] + r * d)).norm();
      if (dist <= best) {  // ties: the first edge in id order (edges listed ascending)
        if (dist == best && st.a >= 0) continue;
        best = dist;
        st = {v, a, b, r};
      }
    }
    if (st.a >= 0) out.push_back(st);
  }
  return out;
}

}  // namespace clothcd::sim
