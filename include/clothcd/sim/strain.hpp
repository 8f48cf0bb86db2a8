#pragma once
/// @file
/// Strain of the cloth's triangles and its limit (docs/simulator.md 1.5, 2.2). Strain is the
/// largest principal stretch of a triangle's deformation against its rest shape, minus 1:
/// sigma_max(F) - 1. The limiter moves the positions a substep ends at, before the collision
/// stage sees them, so that no triangle's principal stretches leave [compression, stretch]:
/// per triangle, F's singular values are clamped and the triangle is moved to the clamped shape
/// about its mass-weighted centroid (Provot 1995, in the singular-value form of Thomaszewski et al.
/// 2009 and Wang et al. 2010), in Gauss-Seidel sweeps over a fixed colouring of the triangles.
/// The integrator runs it on the solve's result and again after each of the first CCD passes'
/// projections (which stop single vertices and so stretch their triangles); the next CCD pass
/// tests what it moved, so the substep's motion stays crossing-free.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim {

/// Where a triangle sits, for the frame figures. A triangle is one kind only, the first that
/// applies in this order.
enum class StrainSite : std::uint8_t {
  Sliver,       ///< a sliver (ClothModel::membrane_active() false)
  Seam,         ///< a vertex of it is in a stitch
  BodyContact,  ///< a vertex of it was held against the body in the frame's last substep
  Elsewhere,
};
[[nodiscard]] const char* strain_site_name(StrainSite s);

/// Strain figures of one state over every triangle with a non-degenerate rest shape (slivers
/// included). Quantiles are nearest rank: the ceil(q n)-th smallest.
struct StrainFigures {
  double median = 0.0;
  double p90 = 0.0;
  double p99 = 0.0;
  double p999 = 0.0;
  double max = 0.0;
  double over_10 = 0.0;  ///< share of triangles strained more than 10%
  int max_face = -1;     ///< the triangle of `max` (the smallest id among equals)
  StrainSite max_site = StrainSite::Elsewhere;
};

/// `body_contact` (one flag per vertex, may be empty) marks the vertices held against the body.
[[nodiscard]] StrainFigures strain_figures(const ClothModel& model, std::span<const Vec3> x,
                                           std::span<const std::uint8_t> body_contact);

/// Strain of every triangle at x (0 for a degenerate rest shape).
[[nodiscard]] std::vector<double> triangle_strains(const ClothModel& model,
                                                   std::span<const Vec3> x);

/// What one limiting pass did.
struct StrainLimitStats {
  int sweeps = 0;             ///< Gauss-Seidel sweeps over the colours
  long long projections = 0;  ///< triangles moved, summed over sweeps
  double residual = 0.0;      ///< largest principal stretch beyond the limits left, as a ratio - 1
};

class StrainLimiter {
 public:
  /// Uses the model's rest shapes (slivers too) and the material's strain_limit and
  /// compression_limit.
  explicit StrainLimiter(const ClothModel& model);

  [[nodiscard]] bool enabled() const { return stretch_ > 0.0 || compression_ > 0.0; }
  /// One flag per vertex: moved by the last apply().
  [[nodiscard]] std::span<const std::uint8_t> moved() const { return touched_; }
  [[nodiscard]] int colors() const { return static_cast<int>(color_start_.size()) - 1; }

  /// Moves the end positions x0 + h v of a substep towards the limits by changing v, in at most
  /// `sweeps` sweeps. Vertices with inverse mass 0 do not move; a vertex with a nonzero `support`
  /// (unit normal of the body under it; may be empty) does not move against it. The first sweep
  /// checks every triangle, or, with `start` (one flag per vertex), the triangles around the
  /// flagged vertices and those the previous call left unsettled; later sweeps check the
  /// triangles around what moved. Bitwise identical for any thread count.
  StrainLimitStats apply(std::span<const Vec3> x0, double h, std::span<const double> inverse_mass,
                         std::span<const Vec3> support, std::span<Vec3> v, int sweeps,
                         std::span<const std::uint8_t> start = {});

 private:
  struct Tri {
    std::array<int, 3> v{};
    Mat2 inv_rest = Mat2::Zero();
    std::array<Vec2, 3> rest{};  // rest corners in the triangle's 2D rest frame
  };
  const ClothModel& model_;
  double stretch_ = 0.0;
  double compression_ = 0.0;
  std::vector<Tri> tris_;         // in colour order
  std::vector<int> color_start_;  // colour c: tris_[color_start_[c] .. color_start_[c + 1])
  std::vector<Vec3> p_;           // end positions being limited
  std::vector<std::uint8_t> moved_, moved_next_, touched_, pending_;
  std::vector<double> excess_;  // per triangle of the last sweep: sigma / limit - 1, or 0
  std::vector<std::uint8_t> projected_;
};

}  // namespace clothcd::sim
