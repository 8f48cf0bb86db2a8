// Finite-difference and invariance checks of the cloth elements, seeded over many scales.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "clothcd/sim/elements.hpp"
#include "grid.hpp"

namespace clothcd::sim {
namespace {

using test::random_vec;

/// A random non-degenerate triangle with edge length about `scale`.
std::array<Vec3, 3> random_triangle(std::mt19937_64& rng, double scale) {
  for (;;) {
    std::array<Vec3, 3> t{random_vec(rng, scale), random_vec(rng, scale), random_vec(rng, scale)};
    const double area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
    if (area > 0.05 * scale * scale) return t;
  }
}

double log_uniform(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  return std::exp(u(rng));
}

TEST(Membrane, GradientAndHessianMatchFiniteDifferences) {
  for (int seed = 0; seed < 40; ++seed) {
    std::mt19937_64 rng(seed);
    const double scale = log_uniform(rng, 1e-3, 1.0);
    const auto rest_pts = random_triangle(rng, scale);
    const MembraneRest rest = membrane_rest_3d(rest_pts[0], rest_pts[1], rest_pts[2]);
    const MembraneModuli mod = membrane_moduli(log_uniform(rng, 1.0, 1e3), 0.3);
    std::array<Vec3, 3> x = rest_pts;
    for (auto& p : x)
      p += random_vec(rng, 0.3 * scale);  // stretched and compressed states
    const MembraneEval e = membrane_eval(x, rest, mod, /*project_psd=*/false);
    const double eps = 1e-6 * scale;
    for (int i = 0; i < 3; ++i) {
      for (int d = 0; d < 3; ++d) {
        auto xp = x, xm = x;
        xp[i][d] += eps;
        xm[i][d] -= eps;
        const MembraneEval ep = membrane_eval(xp, rest, mod, false);
        const MembraneEval em = membrane_eval(xm, rest, mod, false);
        const double fd = (ep.energy - em.energy) / (2 * eps);
        const double gscale = e.gradient[i].norm() + 1e-12 * mod.mu * scale;
        EXPECT_NEAR(fd, e.gradient[i][d], 1e-5 * gscale + 1e-6 * std::abs(fd))
            << "seed " << seed << " vertex " << i << " dim " << d;
        for (int j = 0; j < 3; ++j) {
          const Vec3 fd_h = (ep.gradient[j] - em.gradient[j]) / (2 * eps);
          const Vec3 an = e.hessian[j][i].col(d);
          EXPECT_LE((fd_h - an).norm(), 1e-5 * (an.norm() + mod.mu))
              << "seed " << seed << " block " << j << "," << i << " dim " << d;
        }
      }
    }
  }
}

Eigen::MatrixXd full_hessian(const MembraneEval& e) {
  Eigen::MatrixXd h(9, 9);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      h.block<3, 3>(3 * i, 3 * j) = e.hessian[i][j];
  }
  return h;
}

TEST(Membrane, ProjectedHessianIsPsdAndSymmetric) {
  for (int seed = 0; seed < 40; ++seed) {
    std::mt19937_64 rng(seed);
    const auto rest_pts = random_triangle(rng, 1.0);
    const MembraneRest rest = membrane_rest_3d(rest_pts[0], rest_pts[1], rest_pts[2]);
    const MembraneModuli mod = membrane_moduli(100.0, 0.25);
    std::array<Vec3, 3> x = rest_pts;
    for (auto& p : x)
      p *= 0.6;  // compressed: the exact Hessian is indefinite here
    for (auto& p : x)
      p += random_vec(rng, 0.05);
    const Eigen::MatrixXd h = full_hessian(membrane_eval(x, rest, mod, true));
    EXPECT_LE((h - h.transpose()).norm(), 1e-9 * h.norm()) << "seed " << seed;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(h);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-9 * h.norm()) << "seed " << seed;
  }
}

TEST(Membrane, RigidMotionsGiveZeroForce) {
  for (int seed = 0; seed < 40; ++seed) {
    std::mt19937_64 rng(seed);
    const double scale = log_uniform(rng, 1e-3, 1.0);
    const auto rest_pts = random_triangle(rng, scale);
    const MembraneRest rest = membrane_rest_3d(rest_pts[0], rest_pts[1], rest_pts[2]);
    const MembraneModuli mod = membrane_moduli(260.0, 0.25);
    const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom();
    const Vec3 shift = random_vec(rng, 10.0);
    std::array<Vec3, 3> x;
    for (int i = 0; i < 3; ++i)
      x[i] = q * rest_pts[i] + shift;
    const MembraneEval e = membrane_eval(x, rest, mod, true);
    EXPECT_LE(e.energy, 1e-12 * mod.mu * rest.area) << "seed " << seed;
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(e.gradient[i].norm(), 1e-9 * mod.mu * scale) << "seed " << seed;
    }
  }
}

TEST(Membrane, RestFromPatternMatchesRestFrom3d) {
  std::mt19937_64 rng(7);
  const auto p = random_triangle(rng, 0.1);
  const MembraneRest a = membrane_rest_3d(p[0], p[1], p[2]);
  // The same triangle laid flat: any isometric 2D copy gives the same energies.
  const Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
  const Vec3 u = e1.normalized(), w = e1.cross(e2).cross(e1).normalized();
  const MembraneRest b = membrane_rest_2d(Vec2(1, 2), Vec2(1 + e1.dot(u), 2 + e1.dot(w)),
                                          Vec2(1 + e2.dot(u), 2 + e2.dot(w)));
  EXPECT_NEAR(a.area, b.area, 1e-12);
  std::array<Vec3, 3> x = p;
  for (auto& q : x)
    q += random_vec(rng, 0.02);
  const MembraneModuli mod = membrane_moduli(260.0, 0.25);
  EXPECT_NEAR(membrane_eval(x, a, mod, true).energy, membrane_eval(x, b, mod, true).energy,
              1e-9 * membrane_eval(x, a, mod, true).energy);
}

TEST(Bending, WeightsSumToZeroAndVanishOnPlanarConfigurations) {
  for (int seed = 0; seed < 40; ++seed) {
    std::mt19937_64 rng(seed);
    // A random planar hinge: x0, x1 shared, x2 and x3 on opposite sides.
    const Vec2 a(0, 0), b(1, 0);
    std::uniform_real_distribution<double> u(0.1, 0.9), hgt(0.2, 1.0);
    const Vec2 c(u(rng), hgt(rng)), d(u(rng), -hgt(rng));
    std::array<Vec3, 4> rest{Vec3(a.x(), a.y(), 0), Vec3(b.x(), b.y(), 0), Vec3(c.x(), c.y(), 0),
                             Vec3(d.x(), d.y(), 0)};
    const HingeWeights w = bending_weights(rest, 1e-6, 10.0);
    EXPECT_NEAR(w.k[0] + w.k[1] + w.k[2] + w.k[3], 0.0, 1e-12) << "seed " << seed;
    // Any rigid placement of a planar (even differently shaped) configuration: zero energy.
    const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom();
    std::array<Vec3, 4> x;
    for (int m = 0; m < 4; ++m)
      x[m] = q * rest[m] + Vec3(1, 2, 3);
    EXPECT_LE(bending_energy(w, x), 1e-20) << "seed " << seed;
    // Folding the hinge costs energy.
    std::array<Vec3, 4> folded = rest;
    folded[3].z() = 0.3;
    EXPECT_GT(bending_energy(w, folded), 0.0);
  }
}

TEST(Bending, MatchesHingeEnergyTimesFoldFactor) {
  // docs/simulator.md 1.3: the quadratic energy is the hinge energy 3 l^2 theta^2 / (A0 + A1)
  // times k_b * 4 sin^2(theta/2) / theta^2 for an isometric fold.
  const double kb = 2e-7;
  const std::array<Vec3, 4> rest{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.4, 0.7, 0),
                                 Vec3(0.6, -0.5, 0)};
  const HingeWeights w = bending_weights(rest, kb, 10.0);
  for (double theta : {0.1, 0.5, 1.0, 2.0}) {
    std::array<Vec3, 4> x = rest;
    x[3] = Vec3(0.6, -0.5 * std::cos(theta), 0.5 * std::sin(theta));
    const double a0 = 0.5 * 0.7, a1 = 0.5 * 0.5;
    const double hinge = 3.0 * 1.0 * theta * theta / (a0 + a1);
    const double expected =
        kb * hinge * 4.0 * std::sin(theta / 2) * std::sin(theta / 2) / (theta * theta);
    EXPECT_NEAR(bending_energy(w, x), expected, 1e-9 * expected) << "theta " << theta;
  }
}

TEST(Bending, CotangentsClampedOnSlivers) {
  const std::array<Vec3, 4> rest{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1e-6, 0),
                                 Vec3(0.5, -0.5, 0)};
  const HingeWeights w = bending_weights(rest, 1e-7, 10.0);
  for (double k : w.k)
    EXPECT_LE(std::abs(k), 20.0);
}

}  // namespace
}  // namespace clothcd::sim
