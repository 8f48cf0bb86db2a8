// Contact couplings as penalties in the implicit system.
#include "couplings.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

namespace clothcd::sim {
namespace {
constexpr int kGrain = 1024;
}  // namespace

void CouplingTerms::reset(std::span<const ContactCoupling> couplings,
                          std::span<const double> inverse_mass, double scale) {
  const int n = static_cast<int>(inverse_mass.size());
  list_.clear();
  kappa_.clear();
  for (ContactCoupling c : couplings) {
    const double len = c.n.norm();
    if (!(len > 0.0) || !std::isfinite(len) || !std::isfinite(c.normal_velocity) ||
        !std::isfinite(c.body_velocity))
      continue;
    double w = 0.0;
    bool ok = true;
    for (int k = 0; k < 4; ++k) {
      const int i = c.vertex[k];
      if (i < -1 || i >= n || !std::isfinite(c.c[k])) ok = false;
      if (ok && i >= 0) w += c.c[k] * c.c[k] * inverse_mass[i];
    }
    if (!ok || !(w > 0.0) || !std::isfinite(w)) continue;
    if (std::abs(len - 1.0) > 1e-12) c.n /= len;
    list_.push_back(c);
    kappa_.push_back(scale / w);  // scale x the pair's effective mass along n
  }
  start_.assign(n + 1, 0);
  for (const ContactCoupling& c : list_) {
    for (int i : c.vertex) {
      if (i >= 0) ++start_[i + 1];
    }
  }
  for (int i = 0; i < n; ++i)
    start_[i + 1] += start_[i];
  entry_coupling_.assign(start_[n], 0);
  entry_weight_.assign(start_[n], 0.0);
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  normal_.resize(list_.size());
  for (int j = 0; j < static_cast<int>(list_.size()); ++j) {
    normal_[j] = list_[j].n;
    for (int k = 0; k < 4; ++k) {
      const int i = list_[j].vertex[k];
      if (i < 0) continue;
      entry_coupling_[fill[i]] = j;
      entry_weight_[fill[i]++] = list_[j].c[k];
    }
  }
}

double CouplingTerms::gap_rate(int j, const Vecs& v, const Vecs* dv) const {
  const ContactCoupling& c = list_[j];
  Vec3 r = Vec3::Zero();
  for (int k = 0; k < 4; ++k) {
    const int i = c.vertex[k];
    if (i < 0) continue;
    r += c.c[k] * (dv != nullptr ? Vec3(v[i] + (*dv)[i]) : v[i]);
  }
  return c.n.dot(r) + c.body_velocity - c.normal_velocity;
}

void CouplingTerms::scatter(const std::vector<double>& s, Vecs& y) const {
  const int n = static_cast<int>(start_.size()) - 1;
  tbb::parallel_for(tbb::blocked_range<int>(0, n, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i)
      add_entries(s, i, y[i]);
  });
}

void CouplingTerms::gather(const Vecs& x) const {
  const int m = size();
  scratch_.resize(m);
  tbb::parallel_for(tbb::blocked_range<int>(0, m, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int j = r.begin(); j < r.end(); ++j) {
      if (kappa_[j] == 0.0) {
        scratch_[j] = 0.0;
        continue;
      }
      const ContactCoupling& c = list_[j];
      Vec3 sum = Vec3::Zero();
      for (int k = 0; k < 4; ++k) {
        if (c.vertex[k] >= 0) sum += c.c[k] * x[c.vertex[k]];
      }
      scratch_[j] = kappa_[j] * c.n.dot(sum);
    }
  });
}

void CouplingTerms::add_product(const Vecs& x, Vecs& y) const {
  if (list_.empty()) return;
  gather(x);
  scatter(scratch_, y);
}

void CouplingTerms::add_diagonal(int i, Mat3& d) const {
  for (int e = start_[i]; e < start_[i + 1]; ++e) {
    const int j = entry_coupling_[e];
    if (kappa_[j] == 0.0) continue;
    const double w = entry_weight_[e];
    d += (kappa_[j] * w * w) * (normal_[j] * normal_[j].transpose());
  }
}

void CouplingTerms::add_rhs(const Vecs& v, Vecs& b) const {
  scratch_.resize(list_.size());
  for (int j = 0; j < size(); ++j)  // negated: b -= ... (exact, so bit for bit the same)
    scratch_[j] = kappa_[j] == 0.0 ? 0.0 : -(kappa_[j] * gap_rate(j, v, nullptr));
  scatter(scratch_, b);
}

int CouplingTerms::release_adhesive(const Vecs& v, const Vecs& dv) {
  int released = 0;
  for (int j = 0; j < size(); ++j) {
    if (kappa_[j] > 0.0 && gap_rate(j, v, &dv) > 0.0) {
      kappa_[j] = 0.0;
      ++released;
    }
  }
  return released;
}

}  // namespace clothcd::sim
