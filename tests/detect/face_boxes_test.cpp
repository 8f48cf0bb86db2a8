// The pair loop's box blocks (detail::FaceBoxes, feature_overlaps, face_overlaps, StepFaceBoxes)
// against the separate boxes and the scalar box test: the same overlap bits on random blocks (ties
// and NaN included), and on procedural meshes and random triangles the same blocks as the boxes
// they gather, after full and partial updates, and the same feature pairs from owned_feature_pairs;
// the ownership search masks (search_masks) against their scalar form.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "clothcd/research/procedural.hpp"
#include "detect/step_positions.hpp"
#include "face_boxes_check.hpp"
#include "support/random_gen.hpp"

namespace clothcd::face_boxes_test {
namespace {

TEST(FaceBoxes, VectorOverlapsEqualTheScalarTestOnRandomBlocks) {
  // Coordinates from a few values, so that boxes often touch; some NaN, some infinite.
  const float values[] = {-1.0f,
                          -0.5f,
                          0.0f,
                          -0.0f,
                          0.25f,
                          0.5f,
                          1.0f,
                          std::numeric_limits<float>::infinity(),
                          -std::numeric_limits<float>::infinity(),
                          std::numeric_limits<float>::quiet_NaN()};
  test::Gen gen(11);
  std::size_t vf = 0, ee = 0, faces_overlap = 0;
  for (int n = 0; n < 200000; ++n) {
    detail::FaceBoxes a, b;
    const bool odd = n % 8 == 0;  // now and then NaN and infinities
    const int last = odd ? 9 : 6;
    for (detail::FaceBoxes* x : {&a, &b}) {
      for (int c = 0; c < 3; ++c) {
        for (int lane = 0; lane < 8; ++lane) {
          float lo = values[gen.integer(0, last)], hi = values[gen.integer(0, last)];
          if (!odd && hi < lo) std::swap(lo, hi);
          x->lo[c][lane] = lo;
          x->hi[c][lane] = hi;
        }
      }
    }
    const detail::FeatureOverlaps want = detail::feature_overlaps_scalar(a, b);
    ASSERT_EQ(detail::feature_overlaps(a, b), want) << "block pair " << n;
    ASSERT_EQ(a.face_overlaps(b), detail::overlap(a.face(), b.face())) << "block pair " << n;
    faces_overlap += a.face_overlaps(b) ? 1 : 0;
    vf += static_cast<std::size_t>(std::popcount(want.vf_f) + std::popcount(want.vf_g));
    ee += static_cast<std::size_t>(std::popcount(want.ee));
  }
  EXPECT_GT(vf, 10000u);
  EXPECT_GT(ee, 10000u);
  EXPECT_GT(faces_overlap, 10000u);
  EXPECT_LT(faces_overlap, 190000u);
}

// Every pair of faces of `faces` sharing no vertex through face_boxes_check::check_pair, over a
// few steps with a margin, where a few vertices move between steps (partial updates).
std::size_t check_mesh(const std::vector<Face>& faces, std::vector<Eigen::Vector3d> v0,
                       std::vector<Eigen::Vector3d> v1, test::Gen& gen) {
  const int nv = static_cast<int>(v0.size());
  const Topology topo(faces, nv);
  const detail::Ownership owner(topo);
  detail::FeatureBoxes boxes(true);
  detail::StepPositions step;
  std::size_t n = 0;
  for (double margin : {0.0, 0.0, 1e-3, 1e-3}) {
    step.update(std::span<const Eigen::Vector3d>(v0), std::span<const Eigen::Vector3d>(v1), nv,
                "t0", "t1");
    detail::FeatureContext ctx = face_boxes_check::step_context(topo, step, margin);
    boxes.update(ctx, step);
    face_boxes_check::expect_blocks(ctx);
    for (int f = 0; f < topo.num_faces(); ++f) {
      for (int g = 0; g < topo.num_faces(); ++g) {
        if (f == g || detail::share_vertex(faces[f], faces[g])) continue;
        n += face_boxes_check::check_pair(owner, ctx, f, g);
        if (::testing::Test::HasFailure()) return n;
      }
    }
    for (int i = 0; i < nv; i += 5)
      v1[i] += gen.vec(0.05);
  }
  return n;
}

std::vector<Eigen::Vector3d> rows(const Positions& p) {
  std::vector<Eigen::Vector3d> out;
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    out.emplace_back(p.row(i).transpose());
  return out;
}

TEST(FaceBoxes, SameFeaturePairsAsTheSeparateBoxesOnProceduralMeshes) {
  test::Gen gen(3);
  for (const auto& s : {research::crumpled_sheet(8, 3), research::twisted_strip(24, 3),
                        research::stacked_sheets(4)}) {
    SCOPED_TRACE(s.name);
    EXPECT_GT(check_mesh(s.faces, rows(s.v_t0), rows(s.v_t1), gen), 100u);
  }
}

TEST(FaceBoxes, SameFeaturePairsAsTheSeparateBoxesOnRandomTriangles) {
  // Separate triangles with corners on a coarse grid: their boxes often touch exactly.
  std::size_t n = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    test::Gen gen(seed);
    const int nf = gen.integer(10, 40);
    std::vector<Face> faces;
    std::vector<Eigen::Vector3d> v0, v1;
    for (int f = 0; f < nf; ++f) {
      faces.push_back({3 * f, 3 * f + 1, 3 * f + 2});
      for (int k = 0; k < 3; ++k) {
        v0.push_back(gen.grid(4) * 0.25);
        v1.push_back(v0.back() + gen.grid(1) * 0.25);
      }
    }
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    n += check_mesh(faces, v0, v1, gen);
  }
  EXPECT_GT(n, 1000u);
}

TEST(FaceBoxes, SearchMasksEqualTheScalarFormOnRandomMeshes) {
  // Few vertices and many faces (boundaries, non-manifold edges, duplicates): first faces and
  // apexes that often touch the other face.
  std::size_t touching = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    test::Gen gen(seed);
    const int nv = gen.integer(8, 24);
    std::vector<Face> faces;
    for (int i = gen.integer(4, 40); i > 0; --i) {
      const Face t = gen.face(nv);
      faces.push_back(t);
    }
    const Topology topo(faces, nv);
    const detail::Ownership owner(topo);
    for (int f = 0; f < topo.num_faces(); ++f) {
      for (int g = 0; g < topo.num_faces(); ++g) {
        if (f == g || detail::share_vertex(faces[f], faces[g])) continue;
        const detail::FeatureOverlaps want =
            detail::search_masks_scalar(owner.record(f), owner.record(g));
        ASSERT_EQ(detail::search_masks(owner.record(f), owner.record(g)), want)
            << "seed " << seed << " faces " << f << ", " << g;
        touching += static_cast<std::size_t>(std::popcount(want.vf_f) + std::popcount(want.ee));
      }
    }
  }
  EXPECT_GT(touching, 1000u);
}

}  // namespace
}  // namespace clothcd::face_boxes_test
