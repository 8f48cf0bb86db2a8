// The narrow phase's ownership rule against its definition on the cloth_ball mesh: every third
// face against the faces within two rings of it that share no vertex with it (the pairs whose
// first faces may touch, where the records alone cannot settle ownership) and a random far face.

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "clothcd/mesh/io.hpp"
#include "ownership_check.hpp"
#include "support/data.hpp"
#include "support/random_gen.hpp"

namespace clothcd::ownership_data_test {
namespace {

TEST(Ownership, RecordsAgreeWithTheDefinitionOnClothBall) {
  CLOTHCD_REQUIRE_DATA(root, "cloth-ball");
  const TriangleMesh m = read_mesh(root / "frames/cloth_ball92.ply");
  const Topology t(m.faces, m.num_vertices());
  const detail::Ownership owner(t);
  test::Gen gen(7);
  std::size_t pairs = 0;
  std::vector<int> near;
  for (int f = 0; f < t.num_faces(); f += 3) {
    // Faces within two rings of f that share no vertex with it: the pairs whose first faces may
    // touch, where the full search runs.
    near.clear();
    for (int v : t.faces()[f]) {
      for (int h : t.vertex_faces(v)) {
        for (int w : t.faces()[h]) {
          for (int g : t.vertex_faces(w))
            near.push_back(g);
        }
      }
    }
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    near.push_back(gen.integer(0, t.num_faces() - 1));
    for (int g : near) {
      if (g == f || detail::share_vertex(t.faces()[f], t.faces()[g])) continue;
      pairs += ownership_check::check_pair(t, owner, f, g);
      if (::testing::Test::HasFailure()) return;
    }
  }
  EXPECT_GT(pairs, 100000u);
}

}  // namespace
}  // namespace clothcd::ownership_data_test
