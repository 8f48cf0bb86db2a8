#include "clothcd/research/procedural.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

#include "clothcd/core/error.hpp"

namespace clothcd::research {
namespace {

constexpr double kPi = std::numbers::pi;

// Faces of a grid of (nu + 1) x (nv + 1) vertices starting at vertex `base`, consistently
// oriented, with alternating diagonals.
void grid_faces(int nu, int nv, int base, std::vector<Face>& faces) {
  auto id = [&](int i, int j) { return base + i * (nv + 1) + j; };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0) {
        faces.push_back({a, b, c});
        faces.push_back({a, c, d});
      } else {
        faces.push_back({a, b, d});
        faces.push_back({b, c, d});
      }
    }
  }
}

}  // namespace

ProceduralScene stacked_sheets(int n) {
  ProceduralScene s;
  s.name = "stacked_sheets";
  const int per = (n + 1) * (n + 1);
  s.num_vertices = 2 * per;
  s.v_t0.resize(s.num_vertices, 3);
  s.v_t1.resize(s.num_vertices, 3);
  grid_faces(n, n, 0, s.faces);
  grid_faces(n, n, per, s.faces);
  for (int sheet = 0; sheet < 2; ++sheet) {
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) {
        const int v = sheet * per + i * (n + 1) + j;
        // The upper sheet is shifted by a fraction of a cell so no features align exactly.
        const double x = double(i) / n + (sheet == 1 ? 0.31 / n : 0.0);
        const double y = double(j) / n + (sheet == 1 ? 0.17 / n : 0.0);
        const double wave = 0.02 * std::sin(3.1 * x + 1.3) * std::cos(2.3 * y + 0.4);
        if (sheet == 0) {
          s.v_t0.row(v) << x, y, wave;
          s.v_t1.row(v) << x, y, wave + 0.03;
        } else {
          s.v_t0.row(v) << x, y, 0.1 + wave;
          s.v_t1.row(v) << x, y, -0.05 + 0.5 * wave;
        }
      }
    }
  }
  return s;
}

ProceduralScene winding_strip(int segments, int rings) {
  ProceduralScene s;
  s.name = "winding_strip";
  s.num_vertices = (segments + 1) * (rings + 1);
  s.v_t0.resize(s.num_vertices, 3);
  s.v_t1.resize(s.num_vertices, 3);
  grid_faces(segments, rings, 0, s.faces);
  const double span = 2 * kPi + 1;
  const double a = 0.3, b = 1.5 * a;
  for (int i = 0; i <= segments; ++i) {
    const double u = double(i) / segments;  // phi / span
    const double phi = u * span;
    for (int j = 0; j <= rings; ++j) {
      // The band drifts outwards so the overlapping ends are offset radially.
      const double r = 1.0 + 0.1 * u + 0.3 * double(j) / rings;
      const int v = i * (rings + 1) + j;
      // Heights: a gentle helix at t0 (ends apart), a helix whose last turn drops below the first
      // at t1. All slopes stay small, so every normal stays within a few degrees of +z.
      s.v_t0.row(v) << r * std::cos(phi), r * std::sin(phi), a * u;
      s.v_t1.row(v) << r * std::cos(phi), r * std::sin(phi), a * u - b * u * u;
    }
  }
  return s;
}

ProceduralScene crumpled_sheet(int n, std::uint64_t seed) {
  ProceduralScene s;
  s.name = "crumpled_sheet";
  s.num_vertices = (n + 1) * (n + 1);
  s.v_t0.resize(s.num_vertices, 3);
  s.v_t1.resize(s.num_vertices, 3);
  grid_faces(n, n, 0, s.faces);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  struct Wave {
    double kx, ky, phase, amp;
  };
  // Three random sinusoids per coordinate; gradients well above 1 fold the sheet onto itself.
  std::array<std::array<Wave, 3>, 3> waves;
  for (auto& comp : waves) {
    for (auto& w : comp) {
      w = {2 * kPi * (1 + 3 * uni(rng)), 2 * kPi * (1 + 3 * uni(rng)), 2 * kPi * uni(rng),
           0.06 + 0.08 * uni(rng)};
    }
  }
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const int v = i * (n + 1) + j;
      const double x = double(i) / n, y = double(j) / n;
      const double bump = 0.01 * std::sin(2 * kPi * x) * std::sin(2 * kPi * y);
      s.v_t0.row(v) << x, y, bump;
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        for (const Wave& w : waves[k])
          d[k] += w.amp * std::sin(w.kx * x + w.ky * y + w.phase);
      }
      s.v_t1.row(v) = s.v_t0.row(v) + d.transpose();
    }
  }
  return s;
}

ProceduralScene twisted_strip(int segments, int width) {
  ProceduralScene s;
  s.name = "twisted_strip";
  s.num_vertices = (segments + 1) * (width + 1);
  s.v_t0.resize(s.num_vertices, 3);
  s.v_t1.resize(s.num_vertices, 3);
  grid_faces(segments, width, 0, s.faces);
  const double length = 4.0, half_width = 0.25;
  const double turns = 1.2;  // the coil covers more than one turn, so its ends cross
  const double radius = length / (2 * kPi * turns);
  for (int i = 0; i <= segments; ++i) {
    const double u = double(i) / segments;
    const double tw0 = kPi * u, tw1 = 2.5 * kPi * u;
    for (int j = 0; j <= width; ++j) {
      const double w = half_width * (2.0 * j / width - 1.0);
      const int v = i * (width + 1) + j;
      s.v_t0.row(v) << length * u, w * std::cos(tw0), w * std::sin(tw0);
      const double th = 2 * kPi * turns * u;
      const Eigen::Vector3d radial(std::cos(th), std::sin(th), 0.0);
      const Eigen::Vector3d centre = radius * radial + Eigen::Vector3d(0, 0, 0.05 * u);
      const Eigen::Vector3d p =
          centre + w * (std::cos(tw1) * Eigen::Vector3d::UnitZ() + std::sin(tw1) * radial);
      s.v_t1.row(v) = p.transpose();
    }
  }
  return s;
}

Positions smooth_perturbation(const Positions& positions, double amplitude, double wavelength,
                              std::uint64_t seed) {
  if (!(amplitude >= 0) || !std::isfinite(amplitude) || !(wavelength > 0) ||
      !std::isfinite(wavelength)) {
    throw InputError(fmt::format(
        "perturbation: amplitude must be >= 0 and wavelength > 0 (finite), got {} and {}",
        amplitude, wavelength));
  }
  if (positions.cols() != 3) {
    throw InputError(
        fmt::format("perturbation: positions must be n x 3, got {} columns", positions.cols()));
  }
  // Our own uniform conversion (not std::uniform_real_distribution) so that the field is the same
  // with every standard library.
  std::mt19937_64 rng(seed);
  auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  struct Wave {
    Eigen::Vector3d k;
    double phase;
  };
  std::array<std::array<Wave, 3>, 3> waves;
  const double k = 2 * kPi / wavelength;
  for (auto& comp : waves) {
    for (auto& w : comp) {
      const double z = 2 * uniform() - 1, phi = 2 * kPi * uniform();
      const double r = std::sqrt(1 - z * z);
      w = {k * Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z), 2 * kPi * uniform()};
    }
  }
  Positions out = positions;
  for (Eigen::Index i = 0; i < positions.rows(); ++i) {
    const Eigen::Vector3d x = positions.row(i).transpose();
    for (int c = 0; c < 3; ++c) {
      double d = 0;
      for (const Wave& w : waves[c])
        d += std::sin(w.k.dot(x) + w.phase);
      out(i, c) += amplitude * d / 3.0;  // |d| <= 3
    }
  }
  return out;
}

}  // namespace clothcd::research
