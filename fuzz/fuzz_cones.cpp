// Fuzzes the normal-cone algebra: no crash, no NaN, and every non-saturated merge or leaf cone
// contains what it must contain.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "clothcd/cone.hpp"
#include "fuzz_input.hpp"

namespace {

using clothcd::NormalCone;
using Eigen::Vector3d;

bool finite(const NormalCone& c) {
  return c.axis.allFinite() && std::isfinite(c.half_angle);
}

// Both normalized with stableNorm first: a normal of a tiny triangle (components ~1e-160) has
// subnormal squares, and norm() of its cross product with the axis is then off by 1e-4.
double angle(const Vector3d& a, const Vector3d& b) {
  const Vector3d ua = a / a.stableNorm(), ub = b / b.stableNorm();
  return std::atan2(ua.cross(ub).norm(), ua.dot(ub));
}

// Points on the rim of `c`, checked against `outer` with a rounding allowance.
void check_contains(const NormalCone& outer, const NormalCone& c) {
  if (outer.saturated()) return;
  if (!finite(outer)) std::abort();
  const Vector3d a = c.axis.normalized();
  const Vector3d u = a.unitOrthogonal();
  const Vector3d w = a.cross(u);
  for (int k = 0; k < 8; ++k) {
    const double phi = 2 * std::numbers::pi * k / 8;
    const Vector3d d = std::cos(c.half_angle) * a +
                       std::sin(c.half_angle) * (std::cos(phi) * u + std::sin(phi) * w);
    if (angle(outer.axis, d) > outer.half_angle + 1e-9) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  clothcd::fuzz::ByteReader in(data, size);
  const int mode = in.byte() % 3;
  try {
    if (mode == 0) {
      NormalCone c[2];
      for (auto& ci : c) {
        const Vector3d axis(in.finite_double(), in.finite_double(), in.finite_double());
        if (!(axis.norm() > 1e-150) || !std::isfinite(axis.norm())) return 0;
        ci = NormalCone{axis.normalized(), std::fmod(std::abs(in.finite_double()), 2.0)};
      }
      for (const auto& m : {clothcd::merge_provot(c[0], c[1]), clothcd::merge_tight(c[0], c[1])}) {
        if (std::isnan(m.half_angle)) std::abort();
        check_contains(m, c[0]);
        check_contains(m, c[1]);
      }
    } else if (mode == 1) {
      Vector3d p[6];
      const double scale = std::pow(10.0, static_cast<int>(in.byte() % 41) - 20);
      for (auto& v : p)
        v = Vector3d(in.finite_double(), in.finite_double(), in.finite_double());
      for (auto& v : p)
        v = v.unaryExpr([&](double x) { return std::tanh(x) * scale; });
      for (auto policy : {clothcd::LeafConePolicy::Tang, clothcd::LeafConePolicy::Proposed,
                          clothcd::LeafConePolicy::Exact}) {
        const NormalCone c = clothcd::ccd_leaf_cone(p[0], p[1], p[2], p[3], p[4], p[5], policy);
        if (std::isnan(c.half_angle)) std::abort();
        if (c.saturated()) continue;
        for (int k = 0; k <= 16; ++k) {
          const double t = k / 16.0;
          const Vector3d a = (1 - t) * p[0] + t * p[3], b = (1 - t) * p[1] + t * p[4],
                         cc = (1 - t) * p[2] + t * p[5];
          const Vector3d n = (b - a).cross(cc - a);
          // The normal computed here in double carries an absolute error of a few eps * M^2
          // (M: the largest coordinate); where that is not far below |n| its direction is noise
          // (a fuzzed near-degenerate triangle got the opposite normal), so it is skipped, and
          // otherwise the allowance grows by the angle that error can turn n.
          const double m = std::max({a.lpNorm<Eigen::Infinity>(), b.lpNorm<Eigen::Infinity>(),
                                     cc.lpNorm<Eigen::Infinity>()});
          const double err = 64 * std::numeric_limits<double>::epsilon() * m * m;
          const double len = n.stableNorm();
          if (!(len > 1e3 * err)) continue;
          if (angle(c.axis, n) > c.half_angle + 1e-7 + 2 * err / len) std::abort();
        }
      }
    } else {
      std::vector<Vector3d> dirs;
      while (!in.empty() && dirs.size() < 64) {
        const Vector3d d(in.finite_double(), in.finite_double(), in.finite_double());
        if (d.norm() > 1e-100 && std::isfinite(d.norm())) dirs.push_back(d.normalized());
      }
      const NormalCone c = clothcd::optimal_cone(dirs);
      if (std::isnan(c.half_angle)) std::abort();
      if (!c.saturated()) {
        for (const auto& d : dirs) {
          if (angle(c.axis, d) > c.half_angle + 1e-9) std::abort();
        }
      }
    }
  } catch (const std::invalid_argument&) {
    // Rejected input is an answer, not a failure.
  }
  return 0;
}
