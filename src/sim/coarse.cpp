#include "coarse.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <unordered_map>

#include <fmt/format.h>

#include "clothcd/core/error.hpp"

namespace clothcd::sim {

CoarseSpace::CoarseSpace(const BlockCsr& h, int size) {
  if (size < 2) {
    throw InputError(fmt::format("coarse aggregates need at least 2 vertices, got {}", size));
  }
  const int n = h.rows();
  const bool scalars = !h.scalar_row_start.empty();
  auto for_neighbours = [&](int i, auto&& f) {
    for (int q = h.row_start[i]; q < h.row_start[i + 1]; ++q)
      f(h.cols[q]);
    if (scalars) {
      for (int q = h.scalar_row_start[i]; q < h.scalar_row_start[i + 1]; ++q)
        f(h.scalar_cols[q]);
    }
  };
  // Breadth-first aggregates: compact patches of the surface, seeds in vertex order.
  aggregate_.assign(n, -1);
  members_start_.assign(1, 0);
  std::vector<int> queue;
  for (int seed = 0; seed < n; ++seed) {
    if (aggregate_[seed] >= 0) continue;
    const int a = static_cast<int>(members_start_.size()) - 1;
    queue.assign(1, seed);
    aggregate_[seed] = a;
    for (std::size_t k = 0; k < queue.size() && static_cast<int>(queue.size()) < size; ++k) {
      for_neighbours(queue[k], [&](int j) {
        if (aggregate_[j] >= 0 || static_cast<int>(queue.size()) >= size) return;
        aggregate_[j] = a;
        queue.push_back(j);
      });
    }
    members_.insert(members_.end(), queue.begin(), queue.end());
    members_start_.push_back(static_cast<int>(members_.size()));
  }
  // The fixed coarse blocks: every aggregate pair that a fine block joins.
  const int na = num_aggregates();
  std::unordered_map<std::int64_t, int> block_of;
  auto block = [&](int i, int j) {
    const int a = aggregate_[i], b = aggregate_[j];
    const std::int64_t key = static_cast<std::int64_t>(a) * na + b;
    const auto [it, inserted] = block_of.try_emplace(key, static_cast<int>(blocks_.size()));
    if (inserted) blocks_.emplace_back(a, b);
    return it->second;
  };
  full_block_.resize(h.cols.size());
  scalar_block_.resize(h.scalar_cols.size());
  for (int i = 0; i < n; ++i) {
    for (int q = h.row_start[i]; q < h.row_start[i + 1]; ++q)
      full_block_[q] = block(i, h.cols[q]);
    if (scalars) {
      for (int q = h.scalar_row_start[i]; q < h.scalar_row_start[i + 1]; ++q)
        scalar_block_[q] = block(i, h.scalar_cols[q]);
    }
  }
  diag_block_.resize(na);
  for (int a = 0; a < na; ++a)
    diag_block_[a] = block(members_[members_start_[a]], members_[members_start_[a]]);
}

void CoarseSpace::update(const BlockCsr& h, double c, std::span<const double> mass,
                         const CouplingTerms* couplings) {
  std::vector<Mat3> value(blocks_.size(), Mat3::Zero());
  const int n = h.rows();
  const bool scalars = !h.scalar_row_start.empty();
  for (int i = 0; i < n; ++i) {
    for (int q = h.row_start[i]; q < h.row_start[i + 1]; ++q)
      value[full_block_[q]] += c * h.values[q];
    if (scalars) {
      for (int q = h.scalar_row_start[i]; q < h.scalar_row_start[i + 1]; ++q)
        value[scalar_block_[q]].diagonal().array() += c * h.scalar_values[q];
    }
    value[diag_block_[aggregate_[i]]].diagonal().array() += mass[i];
  }
  std::vector<Eigen::Triplet<double>>& t = triplets_;
  t.clear();
  auto add = [&](int a, int b, const Mat3& m) {
    for (int r = 0; r < 3; ++r) {
      for (int s = 0; s < 3; ++s)
        t.emplace_back(3 * a + r, 3 * b + s, m(r, s));
    }
  };
  for (std::size_t k = 0; k < blocks_.size(); ++k)
    add(blocks_[k].first, blocks_[k].second, value[k]);
  // A coupling's penalty kappa (n . sum_k c_k dv_k)^2 / 2 restricted: its weights summed per
  // aggregate (a pair within one aggregate then cancels, as it does for a translation).
  if (couplings != nullptr) {
    couplings->for_each_active([&](const ContactCoupling& cp, double kappa) {
      std::array<int, 4> agg{};
      std::array<double, 4> w{};
      int m = 0;
      for (int k = 0; k < 4; ++k) {
        if (cp.vertex[k] < 0) continue;
        const int a = aggregate_[cp.vertex[k]];
        int slot = 0;
        while (slot < m && agg[slot] != a)
          ++slot;
        if (slot == m) {
          agg[m] = a;
          w[m++] = 0.0;
        }
        w[slot] += cp.c[k];
      }
      const Mat3 nn = kappa * cp.n * cp.n.transpose();
      for (int k = 0; k < m; ++k) {
        for (int l = 0; l < m; ++l) {
          if (w[k] != 0.0 && w[l] != 0.0) add(agg[k], agg[l], (w[k] * w[l]) * nn);
        }
      }
    });
  }
  const int na = num_aggregates();
  Eigen::SparseMatrix<double> matrix(3 * na, 3 * na);
  matrix.setFromTriplets(t.begin(), t.end());
  factor_.compute(matrix);
  ok_ = factor_.info() == Eigen::Success;
}

void CoarseSpace::solve(std::span<const Vec3> r, std::vector<Vec3>& z) const {
  const int na = num_aggregates();
  z.assign(na, Vec3::Zero());
  if (!ok_) return;
  Eigen::VectorXd rc(3 * na);
  for (int a = 0; a < na; ++a) {
    Vec3 s = Vec3::Zero();
    for (int k = members_start_[a]; k < members_start_[a + 1]; ++k)
      s += r[members_[k]];
    rc.segment<3>(3 * a) = s;
  }
  const Eigen::VectorXd x = factor_.solve(rc);
  for (int a = 0; a < na; ++a)
    z[a] = x.segment<3>(3 * a);
}

}  // namespace clothcd::sim
