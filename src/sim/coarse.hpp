#pragma once
// A coarse correction for the PCG's block-Jacobi preconditioner (two-level, additive): the
// vertices grouped into aggregates of connected vertices, and the system restricted to one
// translation per aggregate, factored once per substep. Block Jacobi removes the error of high
// frequency fast; the smooth error, which the stiff membrane spreads over many vertices, is what
// makes a cold solve long. Off by default (`SolverOptions::coarse_aggregate`): on the garment
// scenes' warm-started solves it saves 20-41% of the iterations but no time on 2 threads
// (docs/simulator.md 2.1).

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <span>
#include <vector>

#include "couplings.hpp"
#include "system.hpp"

namespace clothcd::sim {

class CoarseSpace {
 public:
  /// Aggregates of up to `size` vertices grown breadth-first over the matrix's graph (`h`'s
  /// pattern, full and scalar blocks), seeds in vertex order. size >= 2.
  CoarseSpace(const BlockCsr& h, int size);

  /// A_c = P^T (diag(mass) + c H + K) P, factored; P maps an aggregate's translation onto its
  /// vertices, K: the active couplings' penalties. The filter is left out (A_c stays positive
  /// definite); the preconditioner is applied through it.
  void update(const BlockCsr& h, double c, std::span<const double> mass,
              const CouplingTerms* couplings);

  /// z_a = A_c^-1 (P^T r)_a, per aggregate; deterministic (sums in a fixed order).
  void solve(std::span<const Vec3> r, std::vector<Vec3>& z) const;

  [[nodiscard]] int aggregate_of(int vertex) const { return aggregate_[vertex]; }
  [[nodiscard]] int num_aggregates() const { return static_cast<int>(members_start_.size()) - 1; }

 private:
  std::vector<int> aggregate_;      // per vertex
  std::vector<int> members_start_;  // per aggregate: range into members_
  std::vector<int> members_;
  std::vector<std::pair<int, int>> blocks_;       // the coarse blocks the matrix's pattern gives
  std::vector<int> full_block_;                   // per full slot of h: its coarse block
  std::vector<int> scalar_block_;                 // per scalar slot of h: its coarse block
  std::vector<int> diag_block_;                   // per aggregate: its diagonal coarse block
  std::vector<Eigen::Triplet<double>> triplets_;  // kept between updates
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor_;
  bool ok_ = false;
};

}  // namespace clothcd::sim
