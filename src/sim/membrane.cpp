// StVK membrane on triangles (docs/simulator.md 1.2).
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "clothcd/sim/elements.hpp"

namespace clothcd::sim {

MembraneRest membrane_rest_2d(const Vec2& p0, const Vec2& p1, const Vec2& p2) {
  Mat2 dm;
  dm.col(0) = p1 - p0;
  dm.col(1) = p2 - p0;
  MembraneRest rest;
  const double det = dm.determinant();
  rest.area = 0.5 * std::abs(det);
  // A degenerate rest triangle keeps B = 0: no membrane force (the sliver rule skips it anyway).
  rest.inv_rest = det != 0.0 ? Mat2(dm.inverse()) : Mat2::Zero();
  return rest;
}

MembraneRest membrane_rest_3d(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  const Vec3 e1 = p1 - p0;
  const Vec3 e2 = p2 - p0;
  const double l1 = e1.norm();
  if (l1 == 0.0) return membrane_rest_2d(Vec2::Zero(), Vec2::Zero(), Vec2(0.0, 0.0));
  const Vec3 u = e1 / l1;
  const Vec3 n = e1.cross(e2);
  const double nn = n.norm();
  if (nn == 0.0) return membrane_rest_2d(Vec2::Zero(), Vec2(l1, 0.0), Vec2(e2.dot(u), 0.0));
  const Vec3 w = n.cross(e1).normalized();  // in-plane, orthogonal to e1, towards p2
  return membrane_rest_2d(Vec2::Zero(), Vec2(l1, 0.0), Vec2(e2.dot(u), e2.dot(w)));
}

MembraneModuli membrane_moduli(double youngs_times_thickness, double poisson) {
  return {youngs_times_thickness / (2.0 * (1.0 + poisson)),
          youngs_times_thickness * poisson / (1.0 - poisson * poisson)};
}

MembraneEval membrane_eval(const std::array<Vec3, 3>& x, const MembraneRest& rest,
                           const MembraneModuli& moduli, bool project_psd) {
  const Vec2 g1 = rest.inv_rest.row(0).transpose();
  const Vec2 g2 = rest.inv_rest.row(1).transpose();
  const std::array<Vec2, 3> g{-g1 - g2, g1, g2};
  Eigen::Matrix<double, 3, 2> f =
      x[0] * g[0].transpose() + x[1] * g[1].transpose() + x[2] * g[2].transpose();
  const Mat2 e = 0.5 * (f.transpose() * f - Mat2::Identity());
  const double tr = e.trace();
  const Mat2 s = 2.0 * moduli.mu * e + moduli.lambda * tr * Mat2::Identity();
  const double a = rest.area;

  MembraneEval out;
  out.energy = a * (moduli.mu * e.squaredNorm() + 0.5 * moduli.lambda * tr * tr);

  // Clamp S's eigenvalues for the geometric term: compression makes it indefinite.
  Mat2 s_geo = s;
  if (project_psd) {
    Eigen::SelfAdjointEigenSolver<Mat2> eig(s);
    const Vec2 lam = eig.eigenvalues().cwiseMax(0.0);
    s_geo = eig.eigenvectors() * lam.asDiagonal() * eig.eigenvectors().transpose();
  }
  const Eigen::Matrix<double, 3, 2> fs = f * s;
  const Mat3 fft = f * f.transpose();
  std::array<Vec3, 3> fg;
  for (int i = 0; i < 3; ++i) {
    fg[i] = f * g[i];
    out.gradient[i] = a * (fs * g[i]);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      out.hessian[i][j] =
          a * (g[i].dot(s_geo * g[j]) * Mat3::Identity() + moduli.mu * g[i].dot(g[j]) * fft +
               moduli.mu * fg[j] * fg[i].transpose() + moduli.lambda * fg[i] * fg[j].transpose());
    }
  }
  // sigma_max(F)^2 is the largest eigenvalue of F^T F = 2E + I.
  const Mat2 c = f.transpose() * f;
  const double half_tr = 0.5 * c.trace();
  const double disc = std::sqrt(std::max(0.0, half_tr * half_tr - c.determinant()));
  out.max_stretch = std::sqrt(half_tr + disc) - 1.0;
  return out;
}

}  // namespace clothcd::sim
