#pragma once
/// @file
/// Per-element energies of the cloth model (docs/simulator.md section 1): StVK membrane on
/// triangles, Bergou's quadratic bending on hinges, stitch springs. Pure functions of a few
/// positions, so each is checked against finite differences in isolation.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>

namespace clothcd::sim {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat2 = Eigen::Matrix2d;
using Mat3 = Eigen::Matrix3d;

/// Rest data of one membrane triangle: B = D_m^{-1} of its 2D rest edges and its rest area.
struct MembraneRest {
  Mat2 inv_rest = Mat2::Identity();  ///< B; rows are g1, g2
  double area = 0.0;
};

/// Rest data from the triangle's rest corners in 2D (a flat pattern or a local frame).
[[nodiscard]] MembraneRest membrane_rest_2d(const Vec2& p0, const Vec2& p1, const Vec2& p2);
/// Rest data from 3D rest corners, measured in the triangle's own plane.
[[nodiscard]] MembraneRest membrane_rest_3d(const Vec3& p0, const Vec3& p1, const Vec3& p2);

/// Plane-stress Lame moduli in N/m from the membrane stiffness E*t and Poisson's ratio.
struct MembraneModuli {
  double mu = 0.0;
  double lambda = 0.0;
};
[[nodiscard]] MembraneModuli membrane_moduli(double youngs_times_thickness, double poisson);

/// Energy, gradient (3 vertices) and Hessian (3x3 blocks) of one StVK triangle.
struct MembraneEval {
  double energy = 0.0;
  std::array<Vec3, 3> gradient;
  std::array<std::array<Mat3, 3>, 3> hessian;  ///< hessian[i][j] = d2W / dx_i dx_j
  double max_stretch = 0.0;                    ///< largest singular value of F minus 1
};

/// `project_psd` replaces S by its eigen-clamped S+ in the (G S G^T) (x) I3 term, which makes the
/// element Hessian positive semi-definite; false gives the exact Hessian (for tests).
[[nodiscard]] MembraneEval membrane_eval(const std::array<Vec3, 3>& x, const MembraneRest& rest,
                                         const MembraneModuli& moduli, bool project_psd);

/// Bergou et al. 2006 weights K of a hinge (x0, x1 shared edge, x2 opposite in triangle 0, x3
/// opposite in triangle 1) from rest corners, with |cot| clamped to `cot_clamp` on slivers.
/// The energy is 3 k_b |sum K_m x_m|^2 / (A0 + A1); `scale` returns 6 k_b / (A0 + A1), so the
/// constant Hessian is scale * K K^T (x) I3.
struct HingeWeights {
  std::array<double, 4> k{};
  double scale = 0.0;
};
[[nodiscard]] HingeWeights bending_weights(const std::array<Vec3, 4>& rest, double k_bending,
                                           double cot_clamp);
/// Energy of a hinge with given weights: 0.5 * scale * |sum K_m x_m|^2.
[[nodiscard]] double bending_energy(const HingeWeights& w, const std::array<Vec3, 4>& x);

/// Cotangent of the angle at `a` of triangle (a, b, c).
[[nodiscard]] double cotangent(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace clothcd::sim
