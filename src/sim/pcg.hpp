#pragma once
// Modified PCG of Baraff & Witkin 1998 with a block-Jacobi preconditioner: solves
// (M + c H) dv = b on the subspace left free by per-vertex filters (pins, one constrained
// direction), starting from the prescribed changes. All reductions are deterministic_sum.

#include <cstdint>

#include "coarse.hpp"
#include "couplings.hpp"
#include "system.hpp"

namespace clothcd::sim {

/// Per-vertex filter S_i: identity (free), I - p p^T (one constrained direction), or zero.
struct VertexFilter {
  enum Kind : std::uint8_t { Free, Plane, Pinned };
  std::vector<std::uint8_t> kind;
  std::vector<Vec3> direction;  ///< p for Plane

  void reset(int n) {
    kind.assign(n, Free);
    direction.assign(n, Vec3::Zero());
  }
  [[nodiscard]] Vec3 apply(int i, const Vec3& r) const {
    switch (kind[i]) {
      case Pinned:
        return Vec3::Zero();
      case Plane:
        return r - direction[i] * direction[i].dot(r);
      default:
        return r;
    }
  }
};

struct PcgOptions {
  int max_iterations = 200;
  double tolerance = 1e-3;  ///< on the preconditioned residual norm, relative to the filtered rhs
};

struct PcgResult {
  int iterations = 0;
  double relative_residual = 0.0;
  bool converged = false;
};

/// y = S (diag(mass) + c H + K) x, the system solve_pcg solves; K: the active couplings'
/// penalties (none when `couplings` is null), S: the filter (identity when `filter` is null).
void apply_system(const BlockCsr& h, double c, std::span<const double> mass, const Vecs& x, Vecs& y,
                  const CouplingTerms* couplings = nullptr, const VertexFilter* filter = nullptr);

/// Solves (diag(mass) + c H + K) dv = b. dv holds the start on entry: its constrained components
/// must already be the prescribed changes; the free ones are a warm start. `coarse` (updated for
/// this h, c and mass) adds its correction to the block-Jacobi preconditioner.
PcgResult solve_pcg(const BlockCsr& h, double c, std::span<const double> mass,
                    std::span<const Vec3> b, const VertexFilter& filter, const PcgOptions& options,
                    Vecs& dv, const CouplingTerms* couplings = nullptr,
                    const CoarseSpace* coarse = nullptr);

}  // namespace clothcd::sim
