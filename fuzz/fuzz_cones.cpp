// Fuzzes the normal-cone algebra: no crash, no NaN, and every non-saturated merge or leaf cone
// contains what it must contain.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include "clothcd/cone.hpp"
#include "fuzz_input.hpp"
#include "support/exact_normal.hpp"

namespace {

using clothcd::NormalCone;
using Eigen::Vector3d;

// x, y, z in that order (the order of a constructor's arguments is unspecified).
Vector3d read_vector(clothcd::fuzz::ByteReader& in) {
  const double x = in.finite_double();
  const double y = in.finite_double();
  const double z = in.finite_double();
  return {x, y, z};
}

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
        const Vector3d axis = read_vector(in);
        if (!(axis.norm() > 1e-150) || !std::isfinite(axis.norm())) return 0;
        ci = NormalCone{axis.normalized(), std::fmod(std::abs(in.finite_double()), 2.0)};
      }
      for (const auto& m : {clothcd::merge_provot(c[0], c[1]), clothcd::merge_tight(c[0], c[1])}) {
        if (std::isnan(m.half_angle)) std::abort();
        check_contains(m, c[0]);
        check_contains(m, c[1]);
      }
    } else if (mode == 1) {
      // Scale bytes 0-245 map the coordinates through tanh onto one of 41 decades; 246-255 take
      // them as given, so a seed can hold an exact input.
      const std::uint8_t scale_byte = in.byte();
      const bool raw = scale_byte >= 246;
      const double scale = std::pow(10.0, static_cast<int>(scale_byte % 41) - 20);
      std::array<Vector3d, 3> t0, t1;
      for (auto* side : {&t0, &t1}) {
        for (auto& v : *side) {
          for (int j = 0; j < 3; ++j) {
            const double x = in.finite_double();
            v[j] = raw ? x : std::tanh(x) * scale;
          }
        }
      }
      // Against the exact normal at t = k/16 (computed once for the three policies): no error
      // model of the check's own (one that judged the rounding of interpolated positions by
      // their size at t, not at the ends of the step, once flagged a correct cone).
      std::array<std::optional<Vector3d>, 17> normals;
      bool computed = false;
      for (auto policy : {clothcd::LeafConePolicy::Tang, clothcd::LeafConePolicy::Proposed,
                          clothcd::LeafConePolicy::Exact}) {
        const NormalCone c =
            clothcd::ccd_leaf_cone(t0[0], t0[1], t0[2], t1[0], t1[1], t1[2], policy);
        if (std::isnan(c.half_angle)) std::abort();
        if (c.saturated()) continue;
        if (!computed) {
          for (int k = 0; k <= 16; ++k)
            normals[k] = clothcd::test::exact_normal(t0, t1, k, 16);
          computed = true;
        }
        for (const auto& n : normals) {
          if (n && angle(c.axis, *n) > c.half_angle + 1e-12) std::abort();
        }
      }
    } else {
      std::vector<Vector3d> dirs;
      while (!in.empty() && dirs.size() < 64) {
        const Vector3d d = read_vector(in);
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
