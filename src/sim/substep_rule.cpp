// The substep rule: how many substeps a frame gets from the body's and the cloth's motion.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/sim/scene.hpp"

namespace clothcd::sim {
namespace {

// Nearest-rank quantile q of s (s is reordered).
double quantile(std::vector<double>& s, double q) {
  if (s.empty()) return 0.0;
  const double rank = std::ceil(q * static_cast<double>(s.size()));
  const std::size_t k = rank >= 1.0 ? static_cast<std::size_t>(rank) - 1 : 0;
  const auto at = s.begin() + static_cast<std::ptrdiff_t>(std::min(k, s.size() - 1));
  std::nth_element(s.begin(), at, s.end());
  return *at;
}

// Points sorted into cubic cells of one size, looked up by cell.
class PointGrid {
 public:
  PointGrid(std::span<const Vec3> p, double cell) : p_(p), inv_(1.0 / cell) {
    keyed_.reserve(p.size());
    for (int i = 0; i < static_cast<int>(p.size()); ++i) {
      if (p[i].allFinite()) keyed_.emplace_back(key(cell_of(p[i])), i);
    }
    std::sort(keyed_.begin(), keyed_.end());
  }

  // The nearest point within `radius` of x (ties: the first in a fixed order), -1 if none: cells
  // ring by ring outward, until no unvisited cell can hold a nearer point.
  [[nodiscard]] int nearest(const Vec3& x, double radius) const {
    const std::array<std::int64_t, 3> c = cell_of(x);
    int best = -1;
    double best_d2 = radius * radius;
    const auto rings = static_cast<std::int64_t>(std::ceil(radius * inv_));
    for (std::int64_t k = 0; k <= rings; ++k) {
      for (std::int64_t dx = -k; dx <= k; ++dx) {
        for (std::int64_t dy = -k; dy <= k; ++dy) {
          const bool face = dx == -k || dx == k || dy == -k || dy == k;
          for (std::int64_t dz = -k; dz <= k; dz += face ? 1 : 2 * std::max<std::int64_t>(k, 1)) {
            visit(key({c[0] + dx, c[1] + dy, c[2] + dz}), x, best, best_d2);
          }
        }
      }
      // Points of ring k + 1 lie at least k cells away.
      const double reach = static_cast<double>(k) / inv_;
      if (best >= 0 && best_d2 <= reach * reach) break;
    }
    return best;
  }

 private:
  void visit(std::uint64_t k, const Vec3& x, int& best, double& best_d2) const {
    auto it = std::lower_bound(keyed_.begin(), keyed_.end(), std::pair<std::uint64_t, int>(k, -1));
    for (; it != keyed_.end() && it->first == k; ++it) {
      const double d2 = (p_[it->second] - x).squaredNorm();
      if (d2 < best_d2 || (d2 == best_d2 && best >= 0 && it->second < best)) {
        best_d2 = d2;
        best = it->second;
      }
    }
  }

  // Cells are clamped to +-2^20 per axis (at 5 cm: +-52 km), far beyond any scene.
  static constexpr std::int64_t kHalf = std::int64_t{1} << 20;
  [[nodiscard]] std::array<std::int64_t, 3> cell_of(const Vec3& x) const {
    std::array<std::int64_t, 3> c{};
    for (int k = 0; k < 3; ++k) {
      const double f = std::clamp(std::floor(x[k] * inv_), -static_cast<double>(kHalf),
                                  static_cast<double>(kHalf - 1));
      c[k] = static_cast<std::int64_t>(f);
    }
    return c;
  }
  [[nodiscard]] static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    auto u = [](std::int64_t v) {
      return static_cast<std::uint64_t>(std::clamp<std::int64_t>(v + kHalf, 0, 2 * kHalf - 1));
    };
    return (u(c[0]) << 42) | (u(c[1]) << 21) | u(c[2]);
  }

  std::span<const Vec3> p_;
  double inv_;
  std::vector<std::pair<std::uint64_t, int>> keyed_;
};

}  // namespace

int SubstepRule::count(double body_displacement, double cloth_displacement_estimate) const {
  double n = std::ceil(body_displacement / displacement);
  if (cloth_displacement > 0) {
    n = std::max(n, std::ceil(cloth_displacement_estimate / cloth_displacement));
  }
  if (!(n >= min)) return min;  // also NaN
  return n > max ? max : static_cast<int>(n);
}

double SubstepRule::cloth_speed(std::span<const Vec3> v) const {
  std::vector<double> s(v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    s[i] = v[i].norm();
  return quantile(s, cloth_speed_quantile);
}

double SubstepRule::cloth_speed(std::span<const Vec3> x, std::span<const Vec3> v,
                                std::span<const Vec3> body_x, std::span<const Vec3> body_v,
                                double frame_dt) const {
  if (!(near_body > 0) || body_x.empty() || body_v.size() != body_x.size() ||
      x.size() != v.size()) {
    return cloth_speed(v);
  }
  const PointGrid grid(body_x, near_body);
  // The search stops this many cells out: a vertex that far from the body moves more than
  // kMaxRings * near_body in a frame, and is counted at its own speed.
  constexpr double kMaxRings = 8.0;
  std::vector<double> s(v.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, v.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        // A vertex at no finite place counts at its own speed (NaN or inf
                        // propagate as in the plain rule).
                        if (!x[i].allFinite()) {
                          s[i] = v[i].norm();
                          continue;
                        }
                        const double speed = v[i].norm();
                        const double reach = speed * frame_dt + near_body;
                        if (!(reach <= kMaxRings * near_body)) {
                          s[i] = speed;
                          continue;
                        }
                        const int j = grid.nearest(x[i], reach);
                        s[i] = j < 0 ? 0.0 : std::min(speed, (v[i] - body_v[j]).norm());
                      }
                    });
  return quantile(s, cloth_speed_quantile);
}

}  // namespace clothcd::sim
