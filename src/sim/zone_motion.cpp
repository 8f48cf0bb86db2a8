#include "zone_motion.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace clothcd::sim::detail {
namespace {

// The weighted centroid and mean velocity, or false when the weights sum to nothing.
bool weighted_means(const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                    const std::vector<double>& w, Vec3& xc, Vec3& vc) {
  double wt = 0.0;
  xc.setZero();
  vc.setZero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    wt += w[i];
    xc += w[i] * x[i];
    vc += w[i] * v[i];
  }
  if (!(wt > 0.0)) return false;
  xc /= wt;
  vc /= wt;
  return true;
}

}  // namespace

RigidMotion fit_rigid(const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                      const std::vector<double>& w) {
  RigidMotion r;
  if (!weighted_means(x, v, w, r.xc, r.vc)) return RigidMotion{};
  Vec3 l = Vec3::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Vec3 d = x[i] - r.xc;
    l += w[i] * d.cross(v[i] - r.vc);
    inertia += w[i] * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(inertia);
  const Vec3 ev = es.eigenvalues();
  Vec3 a = es.eigenvectors().transpose() * l;
  for (int k = 0; k < 3; ++k)
    a[k] = ev[k] > 1e-12 * std::max(ev[2], 1e-300) ? a[k] / ev[k] : 0.0;
  r.omega = es.eigenvectors() * a;
  return r;
}

std::optional<AffineMotion> fit_affine(const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                                       const std::vector<double>& w, double h,
                                       const AffineLimits& limits) {
  AffineMotion m;
  if (x.size() < 4 || !weighted_means(x, v, w, m.xc, m.vc)) return std::nullopt;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero(), cross = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Vec3 d = x[i] - m.xc;
    cov += w[i] * d * d.transpose();
    cross += w[i] * (v[i] - m.vc) * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  const Vec3 ev = es.eigenvalues();  // ascending
  if (!(ev[0] > limits.min_flatness * limits.min_flatness * ev[2])) return std::nullopt;
  m.a = cross * es.eigenvectors() * ev.cwiseInverse().asDiagonal() * es.eigenvectors().transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h * m.a);
  if (!(svd.singularValues()[0] < limits.max_strain) || !m.a.allFinite()) return std::nullopt;
  return m;
}

}  // namespace clothcd::sim::detail
