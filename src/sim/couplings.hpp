#pragma once
// Contact couplings (clothcd/sim/collision.hpp) as stiff penalties in the implicit system:
// kappa_j (n_j . sum_k c_jk dv_k + g_j)^2 / 2 added to the solve's energy, matrix-free. The
// product gathers per vertex in a fixed order, so it is bitwise independent of the thread count.

#include <vector>

#include "clothcd/sim/collision.hpp"
#include "system.hpp"

namespace clothcd::sim {

class CouplingTerms {
 public:
  /// Keeps the valid couplings (vertices in range or -1, at least one with inverse mass > 0,
  /// finite weights and velocities, nonzero normal, made unit) and gives each the stiffness
  /// `scale` times its effective mass. All start active.
  void reset(std::span<const ContactCoupling> couplings, std::span<const double> inverse_mass,
             double scale);

  [[nodiscard]] bool empty() const { return list_.empty(); }
  [[nodiscard]] int size() const { return static_cast<int>(list_.size()); }

  /// y += sum over active j of kappa_j c_jk n_j (n_j . sum_k c_jk x_k).
  void add_product(const Vecs& x, Vecs& y) const;
  /// add_product in two halves, for a caller that fuses the second into its own pass over the
  /// vertices: gather(x) keeps kappa_j n_j . sum_k c_jk x_k per coupling, then add_gathered(i, y_i)
  /// does vertex i's share of the sum (the same operations in the same order as add_product).
  void gather(const Vecs& x) const;
  void add_gathered(int i, Vec3& y) const { add_entries(scratch_, i, y); }
  /// d += the active couplings' block on vertex i's diagonal.
  void add_diagonal(int i, Mat3& d) const;
  /// b -= sum over active j of kappa_j c_jk n_j g_j, with g_j the coupling's relative normal
  /// velocity at v minus its target: the right-hand side for dv.
  void add_rhs(const Vecs& v, Vecs& b) const;
  /// Lets go every active coupling whose pair separates faster than its target at v + dv (its
  /// penalty would hold the pair together); returns how many.
  int release_adhesive(const Vecs& v, const Vecs& dv);
  /// f(coupling, kappa) for every active coupling, in order (normals unit).
  template <typename F>
  void for_each_active(F&& f) const {
    for (std::size_t j = 0; j < list_.size(); ++j) {
      if (kappa_[j] != 0.0) f(list_[j], kappa_[j]);
    }
  }

 private:
  [[nodiscard]] double gap_rate(int j, const Vecs& v, const Vecs* dv) const;
  /// y_i += sum over i's entries (j, k) of c_jk s_j n_j, per vertex in a fixed order.
  void scatter(const std::vector<double>& s, Vecs& y) const;
  void add_entries(const std::vector<double>& s, int i, Vec3& y) const {
    for (int e = start_[i]; e < start_[i + 1]; ++e) {
      const int j = entry_coupling_[e];
      if (s[j] != 0.0) y += (entry_weight_[e] * s[j]) * normal_[j];
    }
  }

  std::vector<ContactCoupling> list_;
  std::vector<double> kappa_;  // 0 once let go
  // Per vertex a range of entries, each a coupling j and the vertex's weight c_jk in it, and per
  // coupling its normal: compact copies of list_ for the product's inner loop.
  std::vector<int> start_;
  std::vector<int> entry_coupling_;
  std::vector<double> entry_weight_;
  std::vector<Vec3> normal_;
  mutable std::vector<double> scratch_;  // per coupling, reused by every product of the solve
};

}  // namespace clothcd::sim
