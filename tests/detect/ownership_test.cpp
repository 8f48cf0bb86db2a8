// The narrow phase's ownership rule (owned_feature_pairs over the faces' records) against its
// definition, vf_representative and ee_representative: for every pair of faces sharing no vertex,
// the same VF and EE pairs with the right vertices, on procedural meshes and on random meshes with
// boundaries, non-manifold edges, duplicate faces and any vertex order.

#include <gtest/gtest.h>

#include <vector>

#include "clothcd/research/procedural.hpp"
#include "ownership_check.hpp"
#include "support/random_gen.hpp"

namespace clothcd::ownership_test {
namespace {

using ownership_check::check_all_pairs;

TEST(Ownership, RecordsAgreeWithTheDefinitionOnProceduralMeshes) {
  for (const auto& s : {research::crumpled_sheet(8, 3), research::twisted_strip(24, 3),
                        research::winding_strip(24, 2), research::stacked_sheets(4)}) {
    SCOPED_TRACE(s.name);
    const Topology t(s.faces, s.num_vertices);
    EXPECT_GT(check_all_pairs(t), 0u);
  }
}

TEST(Ownership, RecordsAgreeWithTheDefinitionOnRandomMeshes) {
  // Few vertices and many faces: boundaries, edges of three or more faces, duplicate faces,
  // vertices whose first face is far from the others, faces listed in any order.
  std::size_t pairs = 0, nonmanifold = 0;
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    test::Gen gen(seed);
    const int nv = gen.integer(8, 24);
    const int nf = gen.integer(4, 40);
    std::vector<Face> faces;
    for (int i = 0; i < nf; ++i) {
      const Face t = gen.face(nv);
      faces.push_back(t);
      if (gen.integer(0, 9) == 0) faces.push_back({t[2], t[0], t[1]});  // a duplicate
    }
    const Topology t(faces, nv);
    nonmanifold += static_cast<std::size_t>(t.num_nonmanifold_edges());
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    pairs += check_all_pairs(t);
  }
  EXPECT_GT(pairs, 1000u);
  EXPECT_GT(nonmanifold, 10u);
}

}  // namespace
}  // namespace clothcd::ownership_test
