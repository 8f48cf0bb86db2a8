#include "clothcd/mesh/sewing.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <utility>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/topology.hpp"

namespace clothcd {
namespace {

using Vec3 = Eigen::Vector3d;

// Uniform grid over points: cell -> point ids in insertion order.
class PointGrid {
 public:
  explicit PointGrid(double cell) : inv_cell_(1.0 / cell) {}

  struct Cell {
    std::int64_t x, y, z;
    bool operator==(const Cell&) const = default;
  };

  [[nodiscard]] Cell cell_of(const Vec3& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x() * inv_cell_)),
            static_cast<std::int64_t>(std::floor(p.y() * inv_cell_)),
            static_cast<std::int64_t>(std::floor(p.z() * inv_cell_))};
  }
  void insert(const Vec3& p, int id) { cells_[cell_of(p)].push_back(id); }

  /// Calls fn(id) for every point in the cells overlapping the box [lo, hi].
  template <class Fn>
  void for_each_in_box(const Vec3& lo, const Vec3& hi, Fn&& fn) const {
    const Cell a = cell_of(lo), b = cell_of(hi);
    for (std::int64_t x = a.x; x <= b.x; ++x) {
      for (std::int64_t y = a.y; y <= b.y; ++y) {
        for (std::int64_t z = a.z; z <= b.z; ++z) {
          const auto it = cells_.find(Cell{x, y, z});
          if (it == cells_.end()) continue;
          for (int id : it->second)
            fn(id);
        }
      }
    }
  }

 private:
  struct CellHash {
    std::size_t operator()(const Cell& c) const {
      auto h = static_cast<std::uint64_t>(c.x) * 0x9E3779B97F4A7C15ull;
      h ^= static_cast<std::uint64_t>(c.y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
      h ^= static_cast<std::uint64_t>(c.z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
      return static_cast<std::size_t>(h);
    }
  };
  double inv_cell_;
  std::unordered_map<Cell, std::vector<int>, CellHash> cells_;
};

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

// Union keeping the smaller id as the root, so each cluster's root is its smallest member.
void unite(std::vector<int>& parent, int a, int b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a != b) parent[std::max(a, b)] = std::min(a, b);
}

void record_before(const TriangleMesh& mesh, SewingReport& report) {
  validate_mesh(mesh, "sewing input");
  const Topology topo(mesh.faces, mesh.num_vertices());
  report.components_before = topo.num_components();
  report.boundary_edges_before = topo.num_boundary_edges();
  report.nonmanifold_edges_before = topo.num_nonmanifold_edges();
}

// `topo`: the topology of out.mesh.
void record_after(SewnMesh& out, const Topology& topo) {
  out.report.components_after = topo.num_components();
  out.report.boundary_edges_after = topo.num_boundary_edges();
  out.report.nonmanifold_edges_after = topo.num_nonmanifold_edges();
}

// Renumbers clusters (roots are smallest members) in ascending order and drops collapsed faces.
SewnMesh apply_clusters(const TriangleMesh& mesh, std::vector<int>& parent) {
  SewnMesh out;
  const int nv = mesh.num_vertices();
  out.vertex_map.assign(static_cast<std::size_t>(nv), -1);
  for (int v = 0; v < nv; ++v) {
    const int root = find_root(parent, v);
    if (root == v) {
      out.vertex_map[v] = out.mesh.num_vertices();
      out.mesh.vertices.push_back(mesh.vertices[v]);
    } else {
      out.vertex_map[v] = out.vertex_map[root];  // root < v, already numbered
    }
  }
  out.report.vertices_welded = nv - out.mesh.num_vertices();
  for (const Face& f : mesh.faces) {
    const Face g{out.vertex_map[f[0]], out.vertex_map[f[1]], out.vertex_map[f[2]]};
    if (g[0] == g[1] || g[1] == g[2] || g[0] == g[2]) {
      ++out.report.faces_dropped;
    } else {
      out.mesh.faces.push_back(g);
    }
  }
  return out;
}

std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
         static_cast<std::uint64_t>(std::max(a, b));
}

// Vertices to insert on an edge: (parameter from the smaller to the larger endpoint, vertex).
using Inserts = std::unordered_map<std::uint64_t, std::vector<std::pair<double, int>>>;

// Replaces every face having an edge with inserts by a fan from the opposite corner, repeatedly,
// so a face with inserts on several edges is split edge by edge.
std::vector<Face> split_faces(const std::vector<Face>& faces, Inserts& inserts) {
  for (auto& [key, list] : inserts) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end(),
                           [](const auto& x, const auto& y) { return x.second == y.second; }),
               list.end());
  }
  std::vector<Face> out;
  std::vector<Face> todo(faces.rbegin(), faces.rend());  // popped from the back: input order
  while (!todo.empty()) {
    const Face f = todo.back();
    todo.pop_back();
    int k = 0;
    const std::vector<std::pair<double, int>>* list = nullptr;
    for (; k < 3; ++k) {
      const auto it = inserts.find(edge_key(f[k], f[(k + 1) % 3]));
      if (it != inserts.end()) {
        list = &it->second;
        break;
      }
    }
    if (list == nullptr) {
      out.push_back(f);
      continue;
    }
    const int a = f[k], b = f[(k + 1) % 3], c = f[(k + 2) % 3];
    std::vector<int> chain{a};
    if (a < b) {
      for (const auto& [t, v] : *list)
        chain.push_back(v);
    } else {
      for (auto it = list->rbegin(); it != list->rend(); ++it)
        chain.push_back(it->second);
    }
    chain.push_back(b);
    // Sub-triangles go back on the stack (reverse order keeps them in chain order) because their
    // other two edges may carry inserts too; the split edge's pieces have other keys.
    for (std::size_t i = chain.size() - 1; i-- > 0;) {
      assert(chain[i] != c && chain[i + 1] != c);  // callers never insert a face's own corner
      todo.push_back({chain[i], chain[i + 1], c});
    }
  }
  return out;
}

void check_tolerance(const TriangleMesh& mesh, double tolerance) {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    throw InputError(fmt::format("sewing tolerance {} must be positive and finite", tolerance));
  }
  double extent = 0.0;
  for (const Vec3& p : mesh.vertices)
    extent = std::max(extent, p.cwiseAbs().maxCoeff());
  if (extent / tolerance > 1e15) {
    throw InputError(fmt::format(
        "sewing tolerance {} is too small for coordinates as large as {} (ratio above 1e15)",
        tolerance, extent));
  }
}

SewnMesh weld_only(const TriangleMesh& mesh, double tolerance) {
  check_tolerance(mesh, tolerance);
  const int nv = mesh.num_vertices();
  std::vector<int> parent(static_cast<std::size_t>(nv));
  std::iota(parent.begin(), parent.end(), 0);
  PointGrid grid(tolerance);
  const double tol2 = tolerance * tolerance;
  const Vec3 pad = Vec3::Constant(tolerance);
  for (int v = 0; v < nv; ++v) {
    const Vec3& p = mesh.vertices[v];
    grid.for_each_in_box(p - pad, p + pad, [&](int u) {
      if ((mesh.vertices[u] - p).squaredNorm() <= tol2) unite(parent, u, v);
    });
    grid.insert(p, v);
  }
  return apply_clusters(mesh, parent);
}

// One round of T-junction detection on the current mesh, whose topology is `topo`; returns the
// number of inserts.
int find_t_junctions(const TriangleMesh& mesh, const Topology& topo, double tolerance,
                     Inserts& inserts) {
  std::vector<int> boundary;
  std::vector<char> on_boundary(static_cast<std::size_t>(mesh.num_vertices()), 0);
  double longest = tolerance;
  for (int e = 0; e < topo.num_edges(); ++e) {
    if (topo.edge_faces(e).size() != 1) continue;
    boundary.push_back(e);
    const Edge ed = topo.edges()[e];
    on_boundary[ed[0]] = on_boundary[ed[1]] = 1;
    longest = std::max(longest, (mesh.vertices[ed[1]] - mesh.vertices[ed[0]]).norm());
  }
  // Cells as large as the longest boundary edge: each edge's padded box meets few cells.
  PointGrid grid(longest);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (on_boundary[v]) grid.insert(mesh.vertices[v], v);
  }
  // Each vertex goes to its nearest qualifying edge only.
  struct Best {
    double dist2 = std::numeric_limits<double>::infinity();
    int edge = -1;
    double t = 0;
  };
  std::unordered_map<int, Best> best;
  const double tol2 = tolerance * tolerance;
  const Vec3 pad = Vec3::Constant(tolerance);
  for (int e : boundary) {
    const Edge ed = topo.edges()[e];
    const Face& f = mesh.faces[topo.edge_faces(e)[0]];
    const Vec3& a = mesh.vertices[ed[0]];
    const Vec3& b = mesh.vertices[ed[1]];
    const Vec3 ab = b - a;
    const double len2 = ab.squaredNorm();
    if (len2 <= 4 * tol2) continue;  // no interior point is farther than tol from both ends
    grid.for_each_in_box(a.cwiseMin(b) - pad, a.cwiseMax(b) + pad, [&](int v) {
      if (v == f[0] || v == f[1] || v == f[2]) return;
      const Vec3& p = mesh.vertices[v];
      if ((p - a).squaredNorm() <= tol2 || (p - b).squaredNorm() <= tol2) return;
      const double t = (p - a).dot(ab) / len2;
      if (t <= 0.0 || t >= 1.0) return;
      const double d2 = (a + t * ab - p).squaredNorm();
      if (d2 > tol2) return;
      Best& cur = best[v];
      if (d2 < cur.dist2 || (d2 == cur.dist2 && e < cur.edge)) cur = {d2, e, t};
    });
  }
  int count = 0;
  for (const auto& [v, b] : best) {
    const Edge ed = topo.edges()[b.edge];  // (smaller, larger): t already runs from smaller
    inserts[edge_key(ed[0], ed[1])].emplace_back(b.t, v);
    ++count;
  }
  return count;
}

// weld_only, with the report's counts of the input mesh filled in.
SewnMesh weld_reporting_before(const TriangleMesh& mesh, double tolerance) {
  SewingReport before;
  record_before(mesh, before);
  SewnMesh out = weld_only(mesh, tolerance);
  out.report.components_before = before.components_before;
  out.report.boundary_edges_before = before.boundary_edges_before;
  out.report.nonmanifold_edges_before = before.nonmanifold_edges_before;
  return out;
}

}  // namespace

SewnMesh weld(const TriangleMesh& mesh, double tolerance) {
  SewnMesh out = weld_reporting_before(mesh, tolerance);
  record_after(out, Topology(out.mesh.faces, out.mesh.num_vertices()));
  return out;
}

SewnMesh sew(const TriangleMesh& mesh, double tolerance) {
  SewnMesh out = weld_reporting_before(mesh, tolerance);
  // Each round inserts vertices into edges; a vertex, once inserted, is an endpoint of the
  // pieces, so rounds stop quickly. The cap only guards against a pathological input.
  constexpr int kMaxRounds = 64;
  for (int round = 0; round < kMaxRounds; ++round) {
    const Topology topo(out.mesh.faces, out.mesh.num_vertices());
    Inserts inserts;
    const int n = find_t_junctions(out.mesh, topo, tolerance, inserts);
    if (n == 0) {
      record_after(out, topo);
      return out;
    }
    out.mesh.faces = split_faces(out.mesh.faces, inserts);
    out.report.edges_split += n;
  }
  record_after(out, Topology(out.mesh.faces, out.mesh.num_vertices()));
  return out;
}

SewnMesh sew_stitches(const TriangleMesh& mesh, std::span<const Stitch> stitches,
                      double r_tolerance) {
  SewingReport before;
  record_before(mesh, before);
  const int nv = mesh.num_vertices();
  for (std::size_t s = 0; s < stitches.size(); ++s) {
    const Stitch& st = stitches[s];
    for (int v : {st.i, st.j, st.k}) {
      if (v < 0 || v >= nv) {
        throw InputError(fmt::format(
            "stitch {} ({} {} {} {}): vertex {} is out of range, expected 0 <= index < {}", s, st.i,
            st.j, st.k, st.r, v, nv));
      }
    }
    if (!(st.r >= 0.0 && st.r <= 1.0) || st.j == st.k) {
      throw InputError(fmt::format(
          "stitch {} ({} {} {} {}): expected r in [0, 1] and an edge of two distinct vertices", s,
          st.i, st.j, st.k, st.r));
    }
  }
  std::vector<int> parent(static_cast<std::size_t>(nv));
  std::iota(parent.begin(), parent.end(), 0);
  for (const Stitch& st : stitches) {
    if (st.r <= r_tolerance) unite(parent, st.i, st.j);
    if (st.r >= 1.0 - r_tolerance) unite(parent, st.i, st.k);
  }
  SewnMesh out = apply_clusters(mesh, parent);
  out.report.components_before = before.components_before;
  out.report.boundary_edges_before = before.boundary_edges_before;
  out.report.nonmanifold_edges_before = before.nonmanifold_edges_before;

  const Topology topo(out.mesh.faces, out.mesh.num_vertices());
  Inserts inserts;
  int splits = 0;
  for (std::size_t s = 0; s < stitches.size(); ++s) {
    const Stitch& st = stitches[s];
    if (st.r <= r_tolerance || st.r >= 1.0 - r_tolerance) continue;
    const int v = out.vertex_map[st.i], a = out.vertex_map[st.j], b = out.vertex_map[st.k];
    if (v == a || v == b) continue;  // already welded to an end by another stitch
    if (a == b || topo.find_edge(a, b) < 0) {
      throw InputError(
          fmt::format("stitch {} ({} {} {} {}): vertices {} and {} share no edge of "
                      "the mesh",
                      s, st.i, st.j, st.k, st.r, st.j, st.k));
    }
    for (int f : topo.edge_faces(topo.find_edge(a, b))) {
      const Face& face = out.mesh.faces[f];
      if (face[0] == v || face[1] == v || face[2] == v) {
        throw InputError(
            fmt::format("stitch {} ({} {} {} {}): vertex {} is a corner of face {} "
                        "on the edge it is tied to",
                        s, st.i, st.j, st.k, st.r, st.i, f));
      }
    }
    inserts[edge_key(a, b)].emplace_back(a < b ? st.r : 1.0 - st.r, v);
    ++splits;
  }
  out.mesh.faces = split_faces(out.mesh.faces, inserts);
  out.report.edges_split = splits;
  record_after(out, Topology(out.mesh.faces, out.mesh.num_vertices()));
  return out;
}

}  // namespace clothcd
