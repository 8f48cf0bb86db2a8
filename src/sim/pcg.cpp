// Filtered block-Jacobi PCG.
#include "pcg.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>
#include <cmath>

namespace clothcd::sim {
namespace {
constexpr int kGrain = 1024;

template <typename F>
void for_each_vertex(int n, const F& f) {
  tbb::parallel_for(tbb::blocked_range<int>(0, n, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i)
      f(i);
  });
}

double dot(const Vecs& a, const Vecs& b) {
  return deterministic_sum(static_cast<int>(a.size()), [&](int lo, int hi) {
    double s = 0.0;
    for (int i = lo; i < hi; ++i)
      s += a[i].dot(b[i]);
    return s;
  });
}

}  // namespace

void apply_system(const BlockCsr& h, double c, std::span<const double> mass, const Vecs& x, Vecs& y,
                  const CouplingTerms* couplings, const VertexFilter* filter) {
  // One pass over the rows; per row the operations of multiply, the mass term, the couplings'
  // scatter and the filter in that order, so the bits are those of four separate passes.
  if (couplings != nullptr && couplings->empty()) couplings = nullptr;
  if (couplings != nullptr) couplings->gather(x);
  for_each_vertex(static_cast<int>(x.size()), [&](int i) {
    Vec3 yi = mass[i] * x[i] + c * row_product(h, x, i);
    if (couplings != nullptr) couplings->add_gathered(i, yi);
    y[i] = filter != nullptr ? filter->apply(i, yi) : yi;
  });
}

PcgResult solve_pcg(const BlockCsr& h, double c, std::span<const double> mass,
                    std::span<const Vec3> b, const VertexFilter& filter, const PcgOptions& options,
                    Vecs& dv, const CouplingTerms* couplings, const CoarseSpace* coarse) {
  const int n = static_cast<int>(b.size());
  std::vector<Mat3> pinv(n);
  for_each_vertex(n, [&](int i) {
    Mat3 d = mass[i] * Mat3::Identity() + c * h.values[h.diag[i]];
    if (couplings != nullptr) couplings->add_diagonal(i, d);
    pinv[i] = d.inverse();
  });
  Vecs r(n), s(n), p(n), q(n), fb(n);
  apply_system(h, c, mass, dv, q, couplings);
  for_each_vertex(n, [&](int i) {
    r[i] = filter.apply(i, b[i] - q[i]);
    fb[i] = filter.apply(i, b[i]);
  });
  // With a coarse space: S (D^-1 + P A_c^-1 P^T) S, applied to an already filtered vector. The
  // stopping rule then still measures the residual in the block-Jacobi norm (in `jr`), so that
  // the coarse part, large on smooth residuals, does not loosen it.
  std::vector<Vec3> zc;
  Vecs jr;
  auto two_level = [&](const Vecs& in, Vecs& out) {
    coarse->solve(in, zc);
    jr.resize(n);
    for_each_vertex(n, [&](int i) {
      jr[i] = filter.apply(i, pinv[i] * in[i]);
      out[i] = jr[i] + filter.apply(i, zc[coarse->aggregate_of(i)]);
    });
    return dot(in, jr);
  };
  double delta0 = 0.0, measure = 0.0;
  if (coarse != nullptr) {
    delta0 = two_level(fb, s);
    measure = two_level(r, p);
  } else {
    for_each_vertex(n, [&](int i) { s[i] = pinv[i] * fb[i]; });
    delta0 = dot(fb, s);
    for_each_vertex(n, [&](int i) { p[i] = filter.apply(i, pinv[i] * r[i]); });
  }
  double delta = dot(r, p);
  if (coarse == nullptr) measure = delta;
  PcgResult result;
  const double tol2 = options.tolerance * options.tolerance;
  auto rel = [&](double d) { return delta0 > 0.0 ? std::sqrt(std::max(d, 0.0) / delta0) : 0.0; };
  if (delta0 <= 0.0 || measure <= tol2 * delta0) {
    result.converged = std::isfinite(measure);
    result.relative_residual = rel(measure);
    return result;
  }
  for (int it = 0; it < options.max_iterations; ++it) {
    apply_system(h, c, mass, p, q, couplings, &filter);
    const double pq = dot(p, q);
    if (!(pq > 0.0)) break;  // breakdown: PSD matrix and nonzero p make this impossible in theory
    const double alpha = delta / pq;
    for_each_vertex(n, [&](int i) {
      dv[i] += alpha * p[i];
      r[i] -= alpha * q[i];
      if (coarse == nullptr) s[i] = filter.apply(i, pinv[i] * r[i]);
    });
    if (coarse != nullptr) measure = two_level(r, s);
    const double delta_new = dot(r, s);
    result.iterations = it + 1;
    if (!std::isfinite(delta_new)) {
      delta = measure = delta_new;
      break;
    }
    const double beta = delta_new / delta;
    delta = delta_new;
    if (coarse == nullptr) measure = delta;
    if (measure <= tol2 * delta0) break;
    for_each_vertex(n, [&](int i) { p[i] = s[i] + beta * p[i]; });
  }
  result.relative_residual = rel(measure);
  result.converged = std::isfinite(measure) && measure <= tol2 * delta0;
  return result;
}

}  // namespace clothcd::sim
