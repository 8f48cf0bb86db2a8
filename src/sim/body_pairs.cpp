// Cloth-body feature pairs from the leaf pairs of two BVHs, each pair once.
#include "body_pairs.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "bvh_pairs.hpp"

namespace clothcd::sim::detail {
namespace {

bool uses(std::span<const std::uint8_t> flags, int i) {
  return flags.empty() || flags[i] != 0;
}

// Sorted as 64-bit keys (first id high, second low; ids are >= 0, so the order is the pairs').
void sort_pairs(std::vector<std::pair<int, int>>& l) {
  std::vector<std::uint64_t> keys(l.size());
  for (std::size_t i = 0; i < l.size(); ++i)
    keys[i] =
        static_cast<std::uint64_t>(l[i].first) << 32 | static_cast<std::uint32_t>(l[i].second);
  tbb::parallel_sort(keys.begin(), keys.end());
  for (std::size_t i = 0; i < l.size(); ++i)
    l[i] = {static_cast<int>(keys[i] >> 32), static_cast<int>(keys[i] & 0xffffffffu)};
}

// Boxes of features 0..n-1 (ids(k): their vertices) over a and b, where `use` allows.
template <class Ids>
void fill(std::size_t n, Ids&& ids, std::span<const Vec3> a, std::span<const Vec3> b,
          std::span<const std::uint8_t> use, BoxList& out) {
  out.lo.resize(n);
  out.hi.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 2048),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k != r.end(); ++k) {
                        if (!uses(use, static_cast<int>(k))) continue;
                        Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
                        for (int i : ids(k)) {
                          lo = lo.cwiseMin(a[i]).cwiseMin(b[i]);
                          hi = hi.cwiseMax(a[i]).cwiseMax(b[i]);
                        }
                        out.lo[k] = lo;
                        out.hi[k] = hi;
                      }
                    });
}

}  // namespace

void fill_feature_boxes(const Topology& topo, std::span<const Vec3> a, std::span<const Vec3> b,
                        std::span<const std::uint8_t> vertex_use,
                        std::span<const std::uint8_t> edge_use,
                        std::span<const std::uint8_t> face_use, MeshBoxes& out) {
  fill(
      topo.num_vertices(), [](std::size_t k) { return std::array<int, 1>{static_cast<int>(k)}; }, a,
      b, vertex_use, out.vertex);
  fill(
      topo.num_edges(), [&](std::size_t k) { return topo.edges()[k]; }, a, b, edge_use, out.edge);
  fill(
      topo.num_faces(), [&](std::size_t k) { return topo.faces()[k]; }, a, b, face_use, out.face);
}

void designated_faces(const Topology& topo, std::vector<int>& vertex_face,
                      std::vector<int>& edge_face) {
  auto smallest = [](std::span<const int> fs) {
    return fs.empty() ? -1 : *std::min_element(fs.begin(), fs.end());
  };
  vertex_face.resize(topo.num_vertices());
  for (int v = 0; v < topo.num_vertices(); ++v)
    vertex_face[v] = smallest(topo.vertex_faces(v));
  edge_face.resize(topo.num_edges());
  for (int e = 0; e < topo.num_edges(); ++e)
    edge_face[e] = smallest(topo.edge_faces(e));
}

BodyPairs close_feature_pairs(const PairSide& cloth, const PairSide& body, double gap,
                              std::span<const std::uint8_t> cloth_nodes, const FacePairSkip& skip) {
  auto near = [gap](const BoxList& a, int i, const BoxList& b, int j) {
    return (a.lo[i].array() <= b.hi[j].array() + gap).all() &&
           (b.lo[j].array() <= a.hi[i].array() + gap).all();
  };
  const auto& cf = cloth.topo->faces();
  const auto& bf = body.topo->faces();
  // A feature's box lies in each incident face's, so whenever a feature pair is close, the leaf
  // pair of the two designated faces overlaps and is visited.
  auto visit = [&](int f, int g, BodyPairs& out) {
    if (skip && skip(f, g)) return;
    for (int v : cf[f]) {
      if (cloth.vertex_face[v] == f && uses(cloth.vertex_use, v) &&
          near(cloth.boxes->vertex, v, body.boxes->face, g))
        out.vf_cb.emplace_back(v, g);
    }
    if (uses(cloth.face_use, f)) {
      for (int u : bf[g]) {
        if (body.vertex_face[u] == g && uses(body.vertex_use, u) &&
            near(body.boxes->vertex, u, cloth.boxes->face, f))
          out.vf_bc.emplace_back(u, f);
      }
    }
    for (int a : cloth.topo->face_edges(f)) {
      if (cloth.edge_face[a] != f || !uses(cloth.edge_use, a)) continue;
      for (int b : body.topo->face_edges(g)) {
        if (body.edge_face[b] == g && uses(body.edge_use, b) &&
            near(cloth.boxes->edge, a, body.boxes->edge, b))
          out.ee.emplace_back(a, b);
      }
    }
  };
  tbb::enumerable_thread_specific<BodyPairs> locals;
  for_each_overlap_parallel(*cloth.bvh, *body.bvh, locals, visit, cloth_nodes);
  BodyPairs out;
  for (auto m : {&BodyPairs::vf_cb, &BodyPairs::vf_bc, &BodyPairs::ee}) {
    auto& l = out.*m;
    for (const BodyPairs& p : locals)
      l.insert(l.end(), (p.*m).begin(), (p.*m).end());
    sort_pairs(l);
  }
  return out;
}

}  // namespace clothcd::sim::detail
