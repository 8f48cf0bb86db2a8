#pragma once
// The ownership rule's definition (vf_representative, ee_representative) against the narrow
// phase's owned_feature_pairs for one pair of faces: shared by the ownership tests.

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "detect/narrow.hpp"

namespace clothcd::ownership_check {

using Pairs = std::vector<std::pair<int, int>>;

struct Owned {
  Pairs vf, ee;
};

// The pairs (f, g) owns by definition.
inline Owned expected(const Topology& t, int f, int g) {
  Owned o;
  for (auto [a, b] : {std::pair(f, g), std::pair(g, f)}) {
    for (int v : t.faces()[a]) {
      if (detail::vf_representative(t, v, b) == a) o.vf.emplace_back(v, b);
    }
  }
  for (int ea : t.face_edges(f)) {
    for (int eb : t.face_edges(g)) {
      const int e1 = std::min(ea, eb), e2 = std::max(ea, eb);
      const auto rep = detail::ee_representative(t, e1, e2);
      if (rep == (e1 == ea ? std::pair(f, g) : std::pair(g, f))) o.ee.emplace_back(e1, e2);
    }
  }
  std::sort(o.vf.begin(), o.vf.end());
  std::sort(o.ee.begin(), o.ee.end());
  return o;
}

// What owned_feature_pairs yields, checking the corners and edge vertices it passes along.
inline Owned yielded(const Topology& t, const detail::Ownership& owner, int f, int g) {
  Owned o;
  detail::owned_feature_pairs(
      owner, detail::NoBoxes{}, f, g,
      [&](int v, int face, const Face& corners) {
        EXPECT_EQ(corners, t.faces()[face]);
        o.vf.emplace_back(v, face);
      },
      [&](int e1, int e2, const Edge& a, const Edge& b) {
        EXPECT_LT(e1, e2);
        EXPECT_EQ(a, t.edges()[e1]);
        EXPECT_EQ(b, t.edges()[e2]);
        o.ee.emplace_back(e1, e2);
      });
  std::sort(o.vf.begin(), o.vf.end());
  std::sort(o.ee.begin(), o.ee.end());
  return o;
}

/// Compares the pair (f, g), which must share no vertex; returns the number of feature pairs.
inline std::size_t check_pair(const Topology& t, const detail::Ownership& owner, int f, int g) {
  const Owned want = expected(t, f, g);
  const Owned got = yielded(t, owner, f, g);
  EXPECT_EQ(got.vf, want.vf) << "faces " << f << ", " << g;
  EXPECT_EQ(got.ee, want.ee) << "faces " << f << ", " << g;
  return want.vf.size() + want.ee.size();
}

/// Every pair of faces sharing no vertex, in both orders.
inline std::size_t check_all_pairs(const Topology& t) {
  const detail::Ownership owner(t);
  std::size_t n = 0;
  for (int f = 0; f < t.num_faces(); ++f) {
    for (int g = 0; g < t.num_faces(); ++g) {
      if (f == g || detail::share_vertex(t.faces()[f], t.faces()[g])) continue;
      n += check_pair(t, owner, f, g);
    }
  }
  return n;
}

}  // namespace clothcd::ownership_check
