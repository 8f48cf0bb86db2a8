// What leaves of several triangles would change in the self traversal, counted on the detector's
// own tree: every node of at most k triangles taken as one leaf, whose triangle pairs are then
// box-tested one by one. Prints, per k, the node-pair box tests, the triangle-pair box tests
// inside such leaves and their sum, and checks that every k finds the same overlapping
// triangle pairs as the tree's real leaves (k = 1) and the detector. Then the same for the tree
// made 4-wide. No cone culling
// (Culling::None's walk), so the counts are the traversal's volume, not its time.
//
//   leaf_size_bench T0 T1 [SEW_TOLERANCE [patch|spatial]]
#include <fmt/format.h>

#include <cstdint>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "clothcd/detect/detector.hpp"
#include "clothcd/mesh/io.hpp"
#include "clothcd/mesh/sewing.hpp"

namespace {

using namespace clothcd;

struct Counts {
  std::uint64_t node_tests = 0, triangle_tests = 0, overlapping = 0;
};

// The self traversal with every node of at most k triangles as a leaf, splitting the larger node
// of a pair as the detector does.
class LeafWalk {
 public:
  LeafWalk(const Bvh& bvh, int k) : bvh_(bvh), k_(k) {}

  Counts run() {
    self(0);
    return c_;
  }

 private:
  [[nodiscard]] bool leaf(int n) const {
    const BvhNode& x = bvh_.nodes()[n];
    return x.is_leaf() || x.count <= k_;
  }
  // The real leaf (one triangle) at prim position p.
  [[nodiscard]] const BvhNode& triangle(int p) const {
    return bvh_.nodes()[bvh_.leaf_of_face(bvh_.prim_ids()[p])];
  }
  void test_triangles(int p, int q) {
    ++c_.triangle_tests;
    c_.overlapping += overlap(triangle(p), triangle(q));
  }
  void self(int n) {
    const BvhNode& x = bvh_.nodes()[n];
    if (leaf(n)) {
      for (int p = x.first; p < x.first + x.count; ++p) {
        for (int q = p + 1; q < x.first + x.count; ++q)
          test_triangles(p, q);
      }
      return;
    }
    self(x.left);
    self(x.left + 1);
    pair(x.left, x.left + 1);
  }
  void pair(int a, int b) {
    const BvhNode& x = bvh_.nodes()[a];
    const BvhNode& y = bvh_.nodes()[b];
    ++c_.node_tests;
    if (!overlap(x, y)) return;
    const bool la = leaf(a), lb = leaf(b);
    if (la && lb) {
      if (x.count == 1 && y.count == 1) {  // two triangles: the node test was theirs
        ++c_.overlapping;
        return;
      }
      for (int p = x.first; p < x.first + x.count; ++p) {
        for (int q = y.first; q < y.first + y.count; ++q)
          test_triangles(p, q);
      }
      return;
    }
    if (lb || (!la && x.count >= y.count)) {
      pair(x.left, b);
      pair(x.left + 1, b);
    } else {
      pair(a, y.left);
      pair(a, y.left + 1);
    }
  }

  const Bvh& bvh_;
  int k_;
  Counts c_;
};

// The same walk over the tree made 4-wide: each node's children are its binary grandchildren
// (a leaf child stands for itself), and a visited pair of wide nodes tests all its child pairs'
// boxes at once, as SIMD box tests would (up to 16, four per instruction on AVX2).
class WideWalk {
 public:
  explicit WideWalk(const Bvh& bvh) : bvh_(bvh) {}

  // node_tests: visits of wide node pairs; triangle_tests: child box tests in them.
  Counts run() {
    self(0);
    return c_;
  }

 private:
  [[nodiscard]] int children(int n, int* out) const {
    const BvhNode& x = bvh_.nodes()[n];
    int k = 0;
    for (int c = x.left; c <= x.left + 1; ++c) {
      const BvhNode& y = bvh_.nodes()[c];
      if (y.is_leaf()) {
        out[k++] = c;
      } else {
        out[k++] = y.left;
        out[k++] = y.left + 1;
      }
    }
    return k;
  }
  // Child pairs (a[i], b[j]) whose boxes overlap, walked further.
  void pairs(const int* a, int na, const int* b, int nb, bool same) {
    ++c_.node_tests;
    for (int i = 0; i < na; ++i) {
      for (int j = same ? i + 1 : 0; j < nb; ++j) {
        ++c_.triangle_tests;
        if (overlap(bvh_.nodes()[a[i]], bvh_.nodes()[b[j]])) pair(a[i], b[j]);
      }
    }
  }
  void self(int n) {
    if (bvh_.nodes()[n].is_leaf()) return;
    int s[4];
    const int k = children(n, s);
    for (int i = 0; i < k; ++i)
      self(s[i]);
    pairs(s, k, s, k, true);
  }
  // An overlapping pair of nodes.
  void pair(int a, int b) {
    const BvhNode& x = bvh_.nodes()[a];
    const BvhNode& y = bvh_.nodes()[b];
    if (x.is_leaf() && y.is_leaf()) {
      ++c_.overlapping;
      return;
    }
    int sa[4], sb[4];
    const int na = x.is_leaf() ? (sa[0] = a, 1) : children(a, sa);
    const int nb = y.is_leaf() ? (sb[0] = b, 1) : children(b, sb);
    pairs(sa, na, sb, nb, false);
  }

  const Bvh& bvh_;
  Counts c_;
};

int run(int argc, char** argv) {
  if (argc < 3) {
    fmt::print(stderr, "usage: leaf_size_bench T0 T1 [SEW_TOLERANCE [patch|spatial]]\n");
    return 2;
  }
  TriangleMesh m0 = read_mesh(argv[1]);
  TriangleMesh m1 = read_mesh(argv[2]);
  const double tolerance = argc > 3 ? std::stod(argv[3]) : 0.0;
  if (tolerance > 0) {
    const SewnMesh sewn = sew(m0, tolerance);
    std::vector<int> original(sewn.mesh.num_vertices(), -1);
    for (int i = static_cast<int>(sewn.vertex_map.size()) - 1; i >= 0; --i)
      original[sewn.vertex_map[i]] = i;
    TriangleMesh w1 = sewn.mesh;
    for (int n = 0; n < sewn.mesh.num_vertices(); ++n)
      w1.vertices[n] = m1.vertices[original[n]];
    m0 = sewn.mesh;
    m1 = w1;
  }
  DetectOptions o;
  o.culling = Culling::None;
  o.build = argc > 4 && std::string(argv[4]) == "patch" ? BvhBuild::Patch : BvhBuild::Spatial;
  SelfDetector det(m0.faces, m0.num_vertices(), vertices_matrix(m0), o);
  const DetectResult r = det.detect(vertices_matrix(m0), vertices_matrix(m1));  // swept boxes
  fmt::print("{} triangles, {} build, {} overlapping leaf pairs (adjacent ones included)\n\n",
             m0.faces.size(), o.build == BvhBuild::Patch ? "patch" : "spatial",
             r.stats.triangle_pairs + r.stats.adjacent_pairs);
  fmt::print(
      "| leaf holds up to | node-pair box tests | triangle-pair box tests | sum | "
      "overlapping triangle pairs |\n|---|---|---|---|---|\n");
  std::uint64_t reference = 0, reference_tests = 0;
  for (const int k : {1, 2, 4, 8, 16}) {
    const Counts c = LeafWalk(det.bvh(), k).run();
    if (k == 1) {
      reference = c.overlapping;
      reference_tests = c.node_tests;
      if (reference != r.stats.triangle_pairs + r.stats.adjacent_pairs) {
        fmt::print(stderr, "{} overlapping triangle pairs, the detector's {}\n", reference,
                   r.stats.triangle_pairs + r.stats.adjacent_pairs);
        return 1;
      }
    }
    if (c.overlapping != reference) {
      fmt::print(stderr, "k = {}: {} overlapping triangle pairs, {} with single leaves\n", k,
                 c.overlapping, reference);
      return 1;
    }
    fmt::print("| {} | {} | {} | {} | {} |\n", k, c.node_tests, c.triangle_tests,
               c.node_tests + c.triangle_tests, c.overlapping);
  }
  const Counts w = WideWalk(det.bvh()).run();
  if (w.overlapping != reference) {
    fmt::print(stderr, "4-wide: {} overlapping triangle pairs, {} binary\n", w.overlapping,
               reference);
    return 1;
  }
  fmt::print(
      "\nThe tree made 4-wide (each node's children its grandchildren): {} visits of node pairs "
      "(binary: {}), testing {} child box pairs, the same {} overlapping triangle pairs.\n",
      w.node_tests, reference_tests, w.triangle_tests, w.overlapping);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    fmt::print(stderr, "leaf_size_bench: {}\n", e.what());
    return 1;
  }
}
