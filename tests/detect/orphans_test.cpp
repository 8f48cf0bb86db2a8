// find_orphans against its definition: every VF pair (a vertex on some face, a face without it)
// and EE pair (edges sharing no vertex) that no non-adjacent triangle pair represents
// (vf_representative, ee_representative), by brute force over all feature pairs; on procedural
// meshes and on random ones with boundaries, non-manifold edges, duplicate faces and unused
// vertices, and on meshes small enough that most pairs are orphans.

#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "clothcd/research/procedural.hpp"
#include "detect/narrow.hpp"
#include "detect/orphans.hpp"
#include "support/random_gen.hpp"

namespace clothcd::orphans_test {
namespace {

detail::Orphans by_definition(const Topology& t) {
  detail::Orphans o;
  for (int v = 0; v < t.num_vertices(); ++v) {
    if (t.vertex_faces(v).empty()) continue;
    for (int f = 0; f < t.num_faces(); ++f) {
      if (detail::has_corner(t.faces()[f], v)) continue;
      if (detail::vf_representative(t, v, f) < 0) o.vf.emplace_back(v, f);
    }
  }
  for (int a = 0; a < t.num_edges(); ++a) {
    for (int b = a + 1; b < t.num_edges(); ++b) {
      const Edge &x = t.edges()[a], &y = t.edges()[b];
      if (x[0] == y[0] || x[0] == y[1] || x[1] == y[0] || x[1] == y[1]) continue;
      if (detail::ee_representative(t, a, b).first < 0) o.ee.emplace_back(a, b);
    }
  }
  return o;  // generated in sorted order
}

// Checks one mesh; returns how many orphans it has.
std::size_t check(const Topology& t) {
  const detail::Orphans got = detail::find_orphans(t), want = by_definition(t);
  EXPECT_EQ(got.vf, want.vf);
  EXPECT_EQ(got.ee, want.ee);
  return want.vf.size() + want.ee.size();
}

TEST(Orphans, ProceduralMeshesMatchTheDefinition) {
  for (const auto& s : {research::crumpled_sheet(8, 3), research::twisted_strip(24, 3),
                        research::winding_strip(24, 2), research::stacked_sheets(4)}) {
    SCOPED_TRACE(s.name);
    check(Topology(s.faces, s.num_vertices));
  }
}

TEST(Orphans, RandomMeshesMatchTheDefinition) {
  std::size_t orphans = 0, nonmanifold = 0, duplicates = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    test::Gen gen(seed);
    const int nv = gen.integer(4, 30);  // some vertices unused
    const int nf = gen.integer(1, 45);
    std::vector<Face> faces;
    for (int i = 0; i < nf; ++i) {
      const Face t = gen.face(nv);
      faces.push_back(t);
      if (gen.integer(0, 9) == 0) faces.push_back({t[1], t[2], t[0]});
    }
    const Topology t(faces, nv);
    nonmanifold += static_cast<std::size_t>(t.num_nonmanifold_edges());
    duplicates += static_cast<std::size_t>(t.num_duplicate_faces());
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    orphans += check(t);
  }
  // The cases the definition distinguishes all occurred.
  EXPECT_GT(orphans, 1000u);
  EXPECT_GT(nonmanifold, 10u);
  EXPECT_GT(duplicates, 10u);
}

TEST(Orphans, AFanOfFourHasItsKnownOrphans) {
  // Four triangles around vertex 0 (an octahedron's top). Every face holds vertex 0, so every
  // face pair touches and every feature pair sharing no vertex is an orphan: each rim vertex
  // against the two faces without it (8), each rim edge against the two spokes it misses (8) and
  // the two pairs of opposite rim edges (2).
  const Topology t(std::vector<Face>{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}}, 5);
  check(t);
  const detail::Orphans o = detail::find_orphans(t);
  EXPECT_EQ(o.vf.size(), 8u);
  EXPECT_EQ(o.ee.size(), 10u);
}

}  // namespace
}  // namespace clothcd::orphans_test
