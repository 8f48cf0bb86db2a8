// Topology against brute-force recomputation on hand-made meshes and seeded random grids.

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/topology.hpp"

namespace clothcd {
namespace {

bool has_vertex(const Face& f, int v) {
  return f[0] == v || f[1] == v || f[2] == v;
}

int brute_find(std::vector<int>& parent, int x) {
  return parent[x] == x ? x : parent[x] = brute_find(parent, parent[x]);
}

// Recomputes every query of Topology by brute force and compares exact sets.
void check_against_brute_force(const std::vector<Face>& faces, int nv) {
  const Topology topo(faces, nv);
  const int nf = static_cast<int>(faces.size());
  ASSERT_EQ(topo.num_faces(), nf);
  ASSERT_EQ(topo.num_vertices(), nv);

  // Edges: unique pairs ordered by (larger, smaller).
  std::set<std::pair<int, int>> edge_set;  // (larger, smaller)
  for (const Face& f : faces) {
    for (int k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      edge_set.insert({std::max(a, b), std::min(a, b)});
    }
  }
  std::vector<Edge> expected_edges;
  for (const auto& [hi, lo] : edge_set)
    expected_edges.push_back({lo, hi});
  ASSERT_EQ(topo.edges(), expected_edges);

  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = faces[f][k], b = faces[f][(k + 1) % 3];
      const Edge e = topo.edges()[topo.face_edges(f)[k]];
      EXPECT_EQ(e, (Edge{std::min(a, b), std::max(a, b)})) << "face " << f << " k " << k;
    }
  }

  int boundary = 0, nonmanifold = 0;
  for (int e = 0; e < topo.num_edges(); ++e) {
    const Edge ed = topo.edges()[e];
    std::vector<int> expected;
    for (int f = 0; f < nf; ++f) {
      if (has_vertex(faces[f], ed[0]) && has_vertex(faces[f], ed[1])) expected.push_back(f);
    }
    const auto got = topo.edge_faces(e);
    EXPECT_EQ(std::vector<int>(got.begin(), got.end()), expected) << "edge " << e;
    boundary += expected.size() == 1;
    nonmanifold += expected.size() > 2;
  }
  EXPECT_EQ(topo.num_boundary_edges(), boundary);
  EXPECT_EQ(topo.num_nonmanifold_edges(), nonmanifold);

  int isolated = 0;
  for (int v = 0; v < nv; ++v) {
    std::vector<int> vf, ve;
    for (int f = 0; f < nf; ++f) {
      if (has_vertex(faces[f], v)) vf.push_back(f);
    }
    for (int e = 0; e < topo.num_edges(); ++e) {
      if (topo.edges()[e][0] == v || topo.edges()[e][1] == v) ve.push_back(e);
    }
    const auto gf = topo.vertex_faces(v);
    const auto ge = topo.vertex_edges(v);
    EXPECT_EQ(std::vector<int>(gf.begin(), gf.end()), vf) << "vertex " << v;
    EXPECT_EQ(std::vector<int>(ge.begin(), ge.end()), ve) << "vertex " << v;
    isolated += vf.empty();
  }
  EXPECT_EQ(topo.num_isolated_vertices(), isolated);

  // find_edge over all ordered pairs (both orders), plus out-of-range queries.
  std::map<std::pair<int, int>, int> edge_id;
  for (int e = 0; e < topo.num_edges(); ++e)
    edge_id[{topo.edges()[e][0], topo.edges()[e][1]}] = e;
  for (int a = 0; a < nv; ++a) {
    for (int b = 0; b < nv; ++b) {
      const auto it = edge_id.find({std::min(a, b), std::max(a, b)});
      EXPECT_EQ(topo.find_edge(a, b), it == edge_id.end() ? -1 : it->second) << a << "," << b;
    }
  }
  EXPECT_EQ(topo.find_edge(-1, 0), -1);
  EXPECT_EQ(topo.find_edge(0, nv), -1);

  int duplicates = 0;
  for (int f = 0; f < nf; ++f) {
    Face a = faces[f];
    std::sort(a.begin(), a.end());
    for (int g = 0; g < f; ++g) {
      Face b = faces[g];
      std::sort(b.begin(), b.end());
      if (a == b) {
        ++duplicates;
        break;
      }
    }
  }
  EXPECT_EQ(topo.num_duplicate_faces(), duplicates);

  // Components: union-find over all face pairs that share two vertices (an edge).
  std::vector<int> parent(static_cast<std::size_t>(nf));
  std::iota(parent.begin(), parent.end(), 0);
  for (int f = 0; f < nf; ++f) {
    std::vector<int> neighbors;
    for (int g = 0; g < nf; ++g) {
      int common = 0;
      for (int v : faces[g])
        common += has_vertex(faces[f], v);
      if (g != f && common >= 2) {
        neighbors.push_back(g);
        const int a = brute_find(parent, f), b = brute_find(parent, g);
        parent[std::max(a, b)] = std::min(a, b);
      }
      int shared = 0;
      for (int v : faces[g])
        shared += has_vertex(faces[f], v);
      EXPECT_EQ(topo.faces_share_vertex(f, g), shared > 0);
    }
    EXPECT_EQ(topo.face_neighbors(f), neighbors) << "face " << f;
  }
  std::map<int, int> numbering;
  for (int f = 0; f < nf; ++f) {
    const int r = brute_find(parent, f);
    if (!numbering.count(r)) numbering.emplace(r, static_cast<int>(numbering.size()));
    EXPECT_EQ(topo.face_component(f), numbering[r]) << "face " << f;
  }
  EXPECT_EQ(topo.num_components(), static_cast<int>(numbering.size()));
  // Faces and edges touching flagged vertices (every third vertex, then none).
  for (int every : {3, nv + 1}) {
    std::vector<std::uint8_t> flag(static_cast<std::size_t>(nv), 0);
    for (int v = 1; v < nv; v += every)
      flag[v] = 1;
    std::vector<std::uint8_t> faces_ref(static_cast<std::size_t>(nf), 0), edges_ref;
    for (int f = 0; f < nf; ++f)
      faces_ref[f] = flag[faces[f][0]] || flag[faces[f][1]] || flag[faces[f][2]];
    for (const Edge& e : topo.edges())
      edges_ref.push_back(flag[e[0]] || flag[e[1]]);
    EXPECT_EQ(topo.faces_touching(flag), faces_ref) << "every " << every;
    EXPECT_EQ(topo.edges_touching(flag), edges_ref) << "every " << every;
  }
}

TEST(Topology, SingleTriangle) {
  const Topology topo({{0, 1, 2}}, 3);
  EXPECT_EQ(topo.num_edges(), 3);
  // Sorted by (larger, smaller): (1,0), (2,0), (2,1).
  EXPECT_EQ(topo.edges(), (std::vector<Edge>{{0, 1}, {0, 2}, {1, 2}}));
  EXPECT_EQ(topo.face_edges(0), (std::array<int, 3>{0, 2, 1}));
  EXPECT_EQ(topo.num_boundary_edges(), 3);
  EXPECT_EQ(topo.num_components(), 1);
  check_against_brute_force({{0, 1, 2}}, 3);
}

TEST(Topology, EmptyAndIsolated) {
  const Topology empty({}, 0);
  EXPECT_EQ(empty.num_edges(), 0);
  EXPECT_EQ(empty.num_components(), 0);
  const Topology lonely({}, 4);
  EXPECT_EQ(lonely.num_isolated_vertices(), 4);
  EXPECT_TRUE(lonely.vertex_faces(3).empty());
  check_against_brute_force({{0, 2, 3}}, 5);
}

TEST(Topology, TetrahedronIsClosed) {
  const std::vector<Face> tet{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  const Topology topo(tet, 4);
  EXPECT_EQ(topo.num_edges(), 6);
  EXPECT_EQ(topo.num_boundary_edges(), 0);
  EXPECT_EQ(topo.num_nonmanifold_edges(), 0);
  check_against_brute_force(tet, 4);
}

TEST(Topology, NonManifoldFinAndDuplicates) {
  // Three triangles on edge (0,1), a reversed duplicate, and a second component touching at a
  // vertex only (vertex-connected is not edge-connected).
  const std::vector<Face> faces{{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {2, 1, 0}, {4, 5, 6}};
  const Topology topo(faces, 8);
  EXPECT_EQ(topo.num_nonmanifold_edges(), 1);
  EXPECT_EQ(topo.num_duplicate_faces(), 1);
  EXPECT_EQ(topo.num_components(), 2);
  EXPECT_EQ(topo.face_component(4), 1);
  EXPECT_EQ(topo.num_isolated_vertices(), 1);
  EXPECT_EQ(topo.edge_faces(topo.find_edge(1, 0)).size(), 4u);
  check_against_brute_force(faces, 8);
}

// Components are numbered by their smallest face, whatever the vertex ids.
TEST(Topology, ComponentNumberingBySmallestFace) {
  const std::vector<Face> faces{{10, 11, 12}, {0, 1, 2}, {11, 12, 13}, {1, 2, 3}};
  const Topology topo(faces, 14);
  EXPECT_EQ(topo.face_component(0), 0);
  EXPECT_EQ(topo.face_component(1), 1);
  EXPECT_EQ(topo.face_component(2), 0);
  EXPECT_EQ(topo.face_component(3), 1);
}

std::string error_of(const std::vector<Face>& faces, int nv) {
  try {
    const Topology topo(faces, nv);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Topology, RejectsIndexOutOfRange) {
  const auto msg = error_of({{0, 1, 2}, {1, 2, 3}}, 3);
  EXPECT_NE(msg.find("face 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("3"), std::string::npos) << msg;
}

TEST(Topology, RejectsNegativeIndex) {
  const auto msg = error_of({{0, 1, 2}, {0, 1, 2}, {0, -1, 2}}, 3);
  EXPECT_NE(msg.find("face 2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("-1"), std::string::npos) << msg;
}

TEST(Topology, RejectsRepeatedVertex) {
  const auto msg = error_of({{0, 1, 2}, {2, 1, 2}}, 3);
  EXPECT_NE(msg.find("face 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("repeats"), std::string::npos) << msg;
}

TEST(Topology, RejectsNegativeVertexCount) {
  EXPECT_THROW(Topology({}, -1), InputError);
}

// validate_faces (what mesh readers and sewing check, without building a Topology) throws
// exactly the constructor's error for each bad input, and nothing for good ones.
TEST(Topology, ValidateFacesGivesTheConstructorsErrors) {
  const auto validate_error = [](const std::vector<Face>& faces, int nv) -> std::string {
    try {
      validate_faces(faces, nv);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::vector<std::pair<std::vector<Face>, int>> inputs = {
      {{{0, 1, 2}, {1, 2, 3}}, 3},              // index out of range
      {{{0, 1, 2}, {0, 1, 2}, {0, -1, 2}}, 3},  // negative index, after a duplicate
      {{{0, 1, 2}, {2, 1, 2}}, 3},              // repeated vertex
      {{}, -1},                                 // negative vertex count
      {{{0, 1, 2}, {2, 1, 0}, {0, 3, 1}}, 5},   // valid: duplicate, isolated vertex
      {{}, 0},                                  // valid: empty
  };
  int bad = 0;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const auto& [faces, nv] = inputs[i];
    const std::string want = error_of(faces, nv);
    EXPECT_EQ(validate_error(faces, nv), want) << "input " << i;
    bad += want.empty() ? 0 : 1;
  }
  EXPECT_EQ(bad, 4);
}

// Random grids with random diagonals, holes, duplicates, non-manifold fins, isolated vertices,
// shuffled faces and permuted vertex ids.
TEST(Topology, HubVerticesMatchBruteForce) {
  // Vertices with many edges (fans of 40 and 100 triangles, both orientations, faces shuffled),
  // so that one vertex holds more half-edges than the short in-place sort handles.
  for (const int n : {40, 100}) {
    for (std::uint32_t seed = 0; seed < 4; ++seed) {
      std::mt19937 rng(seed);
      std::vector<Face> faces;
      // The largest id first: then every spoke's half-edges go to the hub.
      const int hub = seed < 2 ? n : static_cast<int>(rng() % static_cast<unsigned>(n + 1));
      std::vector<int> rim;
      for (int v = 0; v <= n; ++v) {
        if (v != hub) rim.push_back(v);
      }
      for (int i = 0; i < n; ++i) {
        const int a = rim[static_cast<std::size_t>(i)],
                  b = rim[static_cast<std::size_t>((i + 1) % n)];
        faces.push_back(rng() % 2 ? Face{hub, a, b} : Face{b, a, hub});
      }
      std::shuffle(faces.begin(), faces.end(), rng);
      check_against_brute_force(faces, n + 1);
    }
  }
}

TEST(Topology, RandomGridsMatchBruteForce) {
  for (std::uint32_t seed = 0; seed < 40; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    const int w = 2 + static_cast<int>(rng() % 6), h = 2 + static_cast<int>(rng() % 6);
    int nv = w * h;
    std::vector<Face> faces;
    for (int i = 0; i + 1 < w; ++i) {
      for (int j = 0; j + 1 < h; ++j) {
        const int a = i * h + j, b = (i + 1) * h + j, c = (i + 1) * h + j + 1, d = i * h + j + 1;
        if (rng() % 2) {
          faces.push_back({a, b, c});
          faces.push_back({a, c, d});
        } else {
          faces.push_back({a, b, d});
          faces.push_back({b, c, d});
        }
      }
    }
    std::shuffle(faces.begin(), faces.end(), rng);
    faces.resize(faces.size() - rng() % (faces.size() / 2 + 1));  // holes, maybe splits
    const std::size_t base = faces.size();
    for (std::size_t i = 0; i < base; ++i) {
      const auto r = rng() % 10;
      if (r == 0) {
        Face dup = faces[i];
        std::rotate(dup.begin(), dup.begin() + 1, dup.end());
        faces.push_back(dup);
      } else if (r == 1) {
        faces.push_back({faces[i][0], faces[i][1], nv++});  // fin on an existing edge
      }
    }
    nv += static_cast<int>(rng() % 3);  // isolated vertices
    std::vector<int> perm(static_cast<std::size_t>(nv));
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), rng);
    for (Face& f : faces) {
      for (int& v : f)
        v = perm[v];
    }
    std::shuffle(faces.begin(), faces.end(), rng);
    check_against_brute_force(faces, nv);
  }
}

}  // namespace
}  // namespace clothcd
