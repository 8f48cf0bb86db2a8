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
  /// d += the active couplings' block on vertex i's diagonal.
  void add_diagonal(int i, Mat3& d) const;
  /// b -= sum over active j of kappa_j c_jk n_j g_j, with g_j the coupling's relative normal
  /// velocity at v minus its target: the right-hand side for dv.
  void add_rhs(const Vecs& v, Vecs& b) const;
  /// Lets go every active coupling whose pair separates faster than its target at v + dv (its
  /// penalty would hold the pair together); returns how many.
  int release_adhesive(const Vecs& v, const Vecs& dv);

 private:
  [[nodiscard]] double gap_rate(int j, const Vecs& v, const Vecs* dv) const;
  /// y_i += sum over i's entries (j, k) of c_jk s_j n_j, per vertex in a fixed order.
  void scatter(const std::vector<double>& s, Vecs& y) const;

  std::vector<ContactCoupling> list_;
  std::vector<double> kappa_;            // 0 once let go
  std::vector<int> start_;               // per vertex: range into entries_
  std::vector<int> entries_;             // coupling * 4 + k
  mutable std::vector<double> scratch_;  // per coupling, reused by every product of the solve
};

}  // namespace clothcd::sim
