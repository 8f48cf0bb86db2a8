// Discrete intersection counting: BVH prefilter, edge-through-triangle test.
#include "clothcd/sim/intersections.hpp"

#include <algorithm>
#include <optional>

#include "bvh/traversal.hpp"
#include "clothcd/bvh/bvh.hpp"
#include "fitted_tree.hpp"
#include "seam_links.hpp"

namespace clothcd::sim {
namespace {

double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).cross(c - a).dot(d - a);
}

// Segment pq passes strictly through the plane of abc (dp, dq: orient(a, b, c, p), (.., q)) at a
// point inside (or on the border of) abc.
bool segment_crosses(const Vec3& p, const Vec3& q, double dp, double dq, const Vec3& a,
                     const Vec3& b, const Vec3& c) {
  if (!((dp > 0 && dq < 0) || (dp < 0 && dq > 0))) return false;
  const double s0 = orient(p, q, a, b);
  const double s1 = orient(p, q, b, c);
  const double s2 = orient(p, q, c, a);
  return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

// Calls fn(f, g, local) for every overlapping leaf pair of a self traversal of `a` (b == nullptr:
// each unordered pair of distinct leaves once) or of a pair traversal of a and b, in parallel;
// returns what fn collected, sorted: the same list whatever the thread count.
template <class Fn>
std::vector<std::pair<int, int>> overlapping(const Bvh& a, const Bvh* b, Fn&& fn) {
  using Local = std::vector<std::pair<int, int>>;
  const Bvh& other = b != nullptr ? *b : a;
  std::vector<std::pair<int, int>> out;
  if (a.nodes().empty() || other.nodes().empty()) return out;
  const auto& na = a.nodes();
  const auto& nb = other.nodes();
  auto tr = ::clothcd::detail::make_traversal(
      std::span<const BvhNode>(na), std::span<const BvhNode>(nb), {}, {},
      [](int, ::clothcd::detail::TraversalCounters&) { return false; },
      [&](int x, int y, Local& local) {
        fn(a.prim_ids()[na[x].first], other.prim_ids()[nb[y].first], local);
      });
  tbb::enumerable_thread_specific<Local> found;
  (void)::clothcd::detail::run_parallel(tr, {0, 0, b == nullptr}, found);
  for (const auto& local : found)
    out.insert(out.end(), local.begin(), local.end());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2) {
  // Two triangles that cross meet in a segment whose ends lie on edges; so some edge of one
  // pierces the other. Each vertex's side of the other plane is computed once for its two edges.
  const double da0 = orient(b0, b1, b2, a0), da1 = orient(b0, b1, b2, a1),
               da2 = orient(b0, b1, b2, a2);
  const double db0 = orient(a0, a1, a2, b0), db1 = orient(a0, a1, a2, b1),
               db2 = orient(a0, a1, a2, b2);
  return segment_crosses(a0, a1, da0, da1, b0, b1, b2) ||
         segment_crosses(a1, a2, da1, da2, b0, b1, b2) ||
         segment_crosses(a2, a0, da2, da0, b0, b1, b2) ||
         segment_crosses(b0, b1, db0, db1, a0, a1, a2) ||
         segment_crosses(b1, b2, db1, db2, a0, a1, a2) ||
         segment_crosses(b2, b0, db2, db0, a0, a1, a2);
}

struct IntersectionCounter::Impl {
  const Topology& cloth;
  detail::SeamLinks links;
  std::optional<Topology> body;
  detail::FittedTree cloth_tree, body_tree;

  Impl(const Topology& c, std::span<const std::pair<int, int>> st, const std::vector<Face>& bf,
       int nb)
      : cloth(c), links(c.num_vertices(), st), cloth_tree(c) {
    if (!bf.empty()) {
      body.emplace(bf, nb);
      body_tree = detail::FittedTree(*body);
    }
  }

  [[nodiscard]] bool skip_self(int f, int g) const {
    const Face& a = cloth.faces()[f];
    const Face& b = cloth.faces()[g];
    return links.any_linked(a, b);  // includes shared vertices
  }
  [[nodiscard]] static bool test(std::span<const Vec3> x, const Face& a, std::span<const Vec3> y,
                                 const Face& b) {
    return triangles_intersect(x[a[0]], x[a[1]], x[a[2]], y[b[0]], y[b[1]], y[b[2]]);
  }
};

IntersectionCounter::IntersectionCounter(const Topology& cloth,
                                         std::span<const std::pair<int, int>> links,
                                         const std::vector<Face>& body_faces, int body_vertices)
    : impl_(std::make_unique<Impl>(cloth, links, body_faces, body_vertices)) {}
IntersectionCounter::~IntersectionCounter() = default;

std::vector<std::pair<int, int>> IntersectionCounter::self_pairs(std::span<const Vec3> x) {
  Impl& im = *impl_;
  RefitOptions ro;
  ro.cones = false;
  im.cloth_tree.refit(x, ro);
  const auto& faces = im.cloth.faces();
  return overlapping(im.cloth_tree.bvh(), nullptr, [&](int f, int g, auto& local) {
    if (im.skip_self(f, g)) return;
    if (Impl::test(x, faces[f], x, faces[g])) local.emplace_back(std::min(f, g), std::max(f, g));
  });
}

std::vector<std::pair<int, int>> IntersectionCounter::body_pairs(std::span<const Vec3> x,
                                                                 std::span<const Vec3> body) {
  Impl& im = *impl_;
  if (!im.body) return {};
  RefitOptions ro;
  ro.cones = false;
  im.cloth_tree.refit(x, ro);
  im.body_tree.refit(body, ro);
  const auto& cf = im.cloth.faces();
  const auto& bf = im.body->faces();
  return overlapping(im.cloth_tree.bvh(), &im.body_tree.bvh(), [&](int f, int g, auto& local) {
    if (Impl::test(x, cf[f], body, bf[g])) local.emplace_back(f, g);
  });
}

std::vector<std::pair<int, int>> IntersectionCounter::self_pairs_brute_force(
    std::span<const Vec3> x) const {
  const Impl& im = *impl_;
  std::vector<std::pair<int, int>> out;
  const auto& faces = im.cloth.faces();
  for (int f = 0; f < im.cloth.num_faces(); ++f) {
    for (int g = f + 1; g < im.cloth.num_faces(); ++g) {
      if (!im.skip_self(f, g) && Impl::test(x, faces[f], x, faces[g])) out.emplace_back(f, g);
    }
  }
  return out;
}

std::vector<std::pair<int, int>> IntersectionCounter::body_pairs_brute_force(
    std::span<const Vec3> x, std::span<const Vec3> body) const {
  const Impl& im = *impl_;
  std::vector<std::pair<int, int>> out;
  if (!im.body) return out;
  const auto& cf = im.cloth.faces();
  const auto& bf = im.body->faces();
  for (int f = 0; f < im.cloth.num_faces(); ++f) {
    for (int g = 0; g < im.body->num_faces(); ++g) {
      if (Impl::test(x, cf[f], body, bf[g])) out.emplace_back(f, g);
    }
  }
  return out;
}

}  // namespace clothcd::sim
