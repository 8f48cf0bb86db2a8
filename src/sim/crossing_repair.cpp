// Undoing self crossings of a cloth's starting shape (docs/simulator.md 3).
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "clothcd/sim/intersections.hpp"

namespace clothcd::sim {
namespace {

struct Move {
  int vertex = -1;
  Vec3 by = Vec3::Zero();
};

// The move that takes the vertex of face `a` lying alone on its side of face `b`'s plane to
// `margin` beyond that plane; none when that vertex is fixed or the plane is degenerate.
std::optional<Move> lone_vertex_move(std::span<const Vec3> x, const Face& a, const Face& b,
                                     std::span<const std::uint8_t> fixed, double margin) {
  const Vec3 n = (x[b[1]] - x[b[0]]).cross(x[b[2]] - x[b[0]]);
  const double len = n.norm();
  if (!(len > 0.0)) return std::nullopt;
  const Vec3 u = n / len;
  std::array<double, 3> d{};
  int above = 0;
  for (int k = 0; k < 3; ++k) {
    d[k] = u.dot(x[a[k]] - x[b[0]]);
    above += d[k] > 0.0 ? 1 : 0;
  }
  // The lone vertex is on the minority side (with a vertex in the plane, the one above it).
  int lone = -1;
  for (int k = 0; k < 3; ++k) {
    const bool up = d[k] > 0.0;
    if ((up && above == 1) || (!up && d[k] < 0.0 && above == 2)) lone = k;
  }
  if (lone < 0) return std::nullopt;
  const int v = a[lone];
  if (!fixed.empty() && fixed[v]) return std::nullopt;
  return Move{v, -(d[lone] + std::copysign(margin, d[lone])) * u};
}

}  // namespace

CrossingRepair repair_self_crossings(std::span<Vec3> x, IntersectionCounter& counter,
                                     const Topology& cloth, std::span<const std::uint8_t> fixed,
                                     double margin, int max_tries) {
  CrossingRepair r;
  std::vector<std::pair<int, int>> pairs = counter.self_pairs(x);
  r.pairs_before = r.pairs_after = static_cast<long long>(pairs.size());
  const auto& faces = cloth.faces();
  int tries = 0;
  bool progress = true;
  while (!pairs.empty() && progress && tries < max_tries) {
    progress = false;
    for (const auto& [f, g] : pairs) {
      std::array<std::optional<Move>, 2> moves{
          lone_vertex_move(x, faces[f], faces[g], fixed, margin),
          lone_vertex_move(x, faces[g], faces[f], fixed, margin)};
      if (moves[0] && moves[1] && moves[1]->by.norm() < moves[0]->by.norm())
        std::swap(moves[0], moves[1]);
      for (const auto& m : moves) {
        if (!m || tries >= max_tries) continue;
        ++tries;
        const Vec3 old = x[m->vertex];
        x[m->vertex] += m->by;
        std::vector<std::pair<int, int>> now = counter.self_pairs(x);
        if (now.size() < pairs.size()) {
          ++r.moves;
          r.largest_move = std::max(r.largest_move, m->by.norm());
          pairs = std::move(now);
          progress = true;
          break;
        }
        x[m->vertex] = old;
      }
      if (progress) break;  // the pair list changed: start over on it
    }
  }
  r.pairs_after = static_cast<long long>(pairs.size());
  return r;
}

}  // namespace clothcd::sim
