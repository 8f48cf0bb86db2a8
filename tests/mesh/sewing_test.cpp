// Sewing: welding against a brute-force clustering, and procedural panels whose sewn topology is
// known from their construction (a coincident seam, a 2:1 T-junction seam, stitch ties).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/sewing.hpp"
#include "clothcd/mesh/topology.hpp"

namespace clothcd {
namespace {

// An nx x ny grid of squares over [x0, x0 + w] x [0, 1] in the z = 0 plane, appended to `mesh`,
// with diagonals alternating so the panel is not symmetric.
void add_panel(TriangleMesh& mesh, int nx, int ny, double x0, double w) {
  const int base = mesh.num_vertices();
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      mesh.vertices.emplace_back(x0 + w * i / nx, static_cast<double>(j) / ny, 0.0);
    }
  }
  const auto id = [&](int i, int j) { return base + i * (ny + 1) + j; };
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      if ((i + j) % 2 == 0) {
        mesh.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        mesh.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        mesh.faces.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        mesh.faces.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  }
}

// Faces as sets of lattice points (positions scaled by `scale` and rounded), orientation kept by
// rotating each face to start at its smallest point.
using LatticeFace = std::array<std::array<long, 2>, 3>;
std::multiset<LatticeFace> lattice_faces(const TriangleMesh& m, double scale) {
  std::multiset<LatticeFace> out;
  for (const Face& f : m.faces) {
    LatticeFace lf;
    for (int k = 0; k < 3; ++k) {
      lf[k] = {std::lround(m.vertices[f[k]].x() * scale),
               std::lround(m.vertices[f[k]].y() * scale)};
    }
    std::rotate(lf.begin(), std::min_element(lf.begin(), lf.end()), lf.end());
    out.insert(lf);
  }
  return out;
}

TEST(Sewing, CoincidentSeamBecomesOneSheet) {
  for (int n : {1, 2, 5}) {
    SCOPED_TRACE("n " + std::to_string(n));
    TriangleMesh panels;
    add_panel(panels, n, n, 0.0, 1.0);
    add_panel(panels, n, n, 1.0, 1.0);
    const SewnMesh sewn = sew(panels, 1e-6);
    EXPECT_EQ(sewn.report.components_before, 2);
    EXPECT_EQ(sewn.report.components_after, 1);
    EXPECT_EQ(sewn.report.vertices_welded, n + 1);
    EXPECT_EQ(sewn.report.edges_split, 0);
    EXPECT_EQ(sewn.report.faces_dropped, 0);
    EXPECT_EQ(sewn.report.boundary_edges_before, 8 * n);
    EXPECT_EQ(sewn.report.boundary_edges_after, 6 * n);
    EXPECT_EQ(sewn.report.nonmanifold_edges_after, 0);
    // Same faces as the panels, now sharing the seam vertices.
    EXPECT_EQ(lattice_faces(sewn.mesh, n), lattice_faces(panels, n));
    EXPECT_EQ(sewn.mesh.num_vertices(), (2 * n + 1) * (n + 1));
    // The map sends each original vertex to a vertex at the same position, and the smallest id
    // of each welded pair keeps its place.
    for (int v = 0; v < panels.num_vertices(); ++v) {
      EXPECT_EQ(sewn.mesh.vertices[sewn.vertex_map[v]], panels.vertices[v]);
    }
    int kept = 0;
    for (int v = 0; v < panels.num_vertices(); ++v) {
      bool first = true;
      for (int u = 0; u < v; ++u)
        first = first && panels.vertices[u] != panels.vertices[v];
      if (first) {
        EXPECT_EQ(sewn.vertex_map[v], kept++) << v;
      }
    }
  }
}

// A coarse n x n panel beside a fine 2n x 2n panel: every coarse seam edge has a fine vertex at
// its midpoint and is split in two.
TEST(Sewing, TJunctionSeamTwoToOne) {
  for (int n : {1, 3, 4}) {
    SCOPED_TRACE("n " + std::to_string(n));
    TriangleMesh panels;
    add_panel(panels, n, n, 0.0, 1.0);
    add_panel(panels, 2 * n, 2 * n, 1.0, 1.0);
    const SewnMesh sewn = sew(panels, 1e-7);
    EXPECT_EQ(sewn.report.components_before, 2);
    EXPECT_EQ(sewn.report.components_after, 1);
    EXPECT_EQ(sewn.report.vertices_welded, n + 1);
    EXPECT_EQ(sewn.report.edges_split, n);
    EXPECT_EQ(sewn.report.boundary_edges_after, 3 * n + 3 * 2 * n);
    EXPECT_EQ(sewn.report.nonmanifold_edges_after, 0);

    // Expected faces: the coarse faces with an edge on x = 1 split at that edge's midpoint from
    // the opposite corner, the fine faces unchanged. Lattice step 1 / (2n) makes all exact.
    const double scale = 2.0 * n;
    std::multiset<LatticeFace> expected;
    TriangleMesh coarse;
    add_panel(coarse, n, n, 0.0, 1.0);
    for (const auto& lf : lattice_faces(coarse, scale)) {
      int k = 0;
      for (; k < 3; ++k) {
        if (lf[k][0] == lf[(k + 1) % 3][0] && lf[k][0] == std::lround(scale)) break;
      }
      if (k == 3) {
        expected.insert(lf);
        continue;
      }
      const auto a = lf[k], b = lf[(k + 1) % 3], c = lf[(k + 2) % 3];
      const std::array<long, 2> m{a[0], (a[1] + b[1]) / 2};
      for (LatticeFace piece : {LatticeFace{a, m, c}, LatticeFace{m, b, c}}) {
        std::rotate(piece.begin(), std::min_element(piece.begin(), piece.end()), piece.end());
        expected.insert(piece);
      }
    }
    TriangleMesh fine_only;
    add_panel(fine_only, 2 * n, 2 * n, 1.0, 1.0);
    for (const auto& lf : lattice_faces(fine_only, scale))
      expected.insert(lf);
    EXPECT_EQ(lattice_faces(sewn.mesh, scale), expected);
  }
}

// The same 2:1 seam sewn from explicit stitch ties gives the same mesh as the geometric sewing.
TEST(Sewing, StitchesMatchGeometricSewing) {
  const int n = 3;
  TriangleMesh panels;
  add_panel(panels, n, n, 0.0, 1.0);
  const int fine_base = panels.num_vertices();
  add_panel(panels, 2 * n, 2 * n, 1.0, 1.0);
  // Coarse seam vertex j is (n, j); fine seam vertex k is (0, k) of the fine panel.
  const auto coarse_id = [&](int j) { return n * (n + 1) + j; };
  std::vector<Stitch> stitches;
  for (int k = 0; k <= 2 * n; ++k) {
    const int fine = fine_base + k;
    if (k % 2 == 0) {
      // Tie to the end of an edge: r = 0 (to j) or r = 1 (to k), both directions exercised.
      if (k < 2 * n) {
        stitches.push_back({fine, coarse_id(k / 2), coarse_id(k / 2 + 1), 0.0});
      } else {
        stitches.push_back({fine, coarse_id(k / 2 - 1), coarse_id(k / 2), 1.0});
      }
    } else {
      stitches.push_back({fine, coarse_id(k / 2 + 1), coarse_id(k / 2), 0.5});
    }
  }
  const SewnMesh by_stitch = sew_stitches(panels, stitches);
  const SewnMesh by_geometry = sew(panels, 1e-7);
  EXPECT_EQ(by_stitch.report.components_after, 1);
  EXPECT_EQ(by_stitch.report.edges_split, n);
  EXPECT_EQ(by_stitch.report.vertices_welded, n + 1);
  EXPECT_EQ(by_stitch.vertex_map, by_geometry.vertex_map);
  EXPECT_EQ(lattice_faces(by_stitch.mesh, 2.0 * n), lattice_faces(by_geometry.mesh, 2.0 * n));
}

TEST(Sewing, CollapsedFacesAreDropped) {
  TriangleMesh m;
  add_panel(m, 1, 1, 0.0, 1.0);
  const int b = m.num_vertices();
  m.vertices.emplace_back(5, 5, 5);
  m.vertices.emplace_back(5 + 1e-9, 5, 5);
  m.vertices.emplace_back(5, 5 + 1e-9, 5);
  m.faces.push_back({b, b + 1, b + 2});
  const SewnMesh sewn = weld(m, 1e-6);
  EXPECT_EQ(sewn.report.faces_dropped, 1);
  EXPECT_EQ(sewn.report.vertices_welded, 2);
  EXPECT_EQ(sewn.mesh.num_faces(), 2);
  EXPECT_EQ(sewn.vertex_map[b + 1], sewn.vertex_map[b]);
}

// Welding against an O(n^2) clustering of random clustered points, over scales.
TEST(Sewing, WeldMatchesBruteForce) {
  for (std::uint32_t seed = 0; seed < 30; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1), lg(-8, 3);
    const double scale = std::pow(10.0, lg(rng));
    const double tol = scale * 1e-3;
    TriangleMesh m;
    const int centres = 5 + static_cast<int>(rng() % 40);
    for (int c = 0; c < centres; ++c) {
      const Eigen::Vector3d centre(u(rng) * scale, u(rng) * scale, u(rng) * scale);
      const int copies = 1 + static_cast<int>(rng() % 3);
      for (int i = 0; i < copies; ++i) {
        // Some copies within tol, some just outside, to exercise the boundary of the test.
        const double r = tol * (rng() % 4 == 0 ? 1.5 : 0.5);
        m.vertices.push_back(centre + r * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized());
      }
    }
    std::shuffle(m.vertices.begin(), m.vertices.end(), rng);
    const int nv = m.num_vertices();
    std::vector<int> parent(static_cast<std::size_t>(nv));
    std::iota(parent.begin(), parent.end(), 0);
    const std::function<int(int)> root = [&](int x) {
      return parent[x] == x ? x : parent[x] = root(parent[x]);
    };
    for (int a = 0; a < nv; ++a) {
      for (int b = 0; b < a; ++b) {
        if ((m.vertices[a] - m.vertices[b]).norm() <= tol) {
          const int ra = root(a), rb = root(b);
          parent[std::max(ra, rb)] = std::min(ra, rb);
        }
      }
    }
    std::vector<int> expected(static_cast<std::size_t>(nv));
    int next = 0;
    for (int v = 0; v < nv; ++v)
      expected[v] = root(v) == v ? next++ : expected[root(v)];
    const SewnMesh sewn = weld(m, tol);
    EXPECT_EQ(sewn.vertex_map, expected);
    EXPECT_EQ(sewn.mesh.num_vertices(), next);
  }
}

TEST(SewingErrors, BadTolerance) {
  TriangleMesh m;
  add_panel(m, 1, 1, 0.0, 1.0);
  EXPECT_THROW((void)weld(m, 0.0), InputError);
  EXPECT_THROW((void)weld(m, -1.0), InputError);
  EXPECT_THROW((void)sew(m, std::nan("")), InputError);
  EXPECT_THROW((void)weld(m, 1e-300), InputError);
}

TEST(SewingErrors, StitchOutOfRange) {
  TriangleMesh m;
  add_panel(m, 1, 1, 0.0, 1.0);
  const std::vector<Stitch> s{{0, 1, 2, 0.5}, {9, 1, 2, 0.5}};
  try {
    (void)sew_stitches(m, s);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("stitch 1"), std::string::npos) << e.what();
  }
}

TEST(SewingErrors, StitchEdgeMissing) {
  TriangleMesh m;
  add_panel(m, 2, 2, 0.0, 1.0);
  add_panel(m, 1, 1, 5.0, 1.0);
  // Vertices 0 and 8 are opposite corners of the first panel: no edge joins them.
  const std::vector<Stitch> s{{9, 0, 8, 0.5}};
  try {
    (void)sew_stitches(m, s);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("share no edge"), std::string::npos) << e.what();
  }
}

TEST(SewingErrors, StitchToOwnTriangle) {
  TriangleMesh m;
  add_panel(m, 1, 1, 0.0, 1.0);
  // Face 0 is (0, 2, 3): tying its corner 3 to its own edge (0, 2) would fold it.
  const std::vector<Stitch> s{{3, 0, 2, 0.5}};
  EXPECT_THROW((void)sew_stitches(m, s), InputError);
}

}  // namespace
}  // namespace clothcd
