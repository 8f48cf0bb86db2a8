// CSR pattern, gather maps and parallel assembly of the implicit system.
#include "system.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cassert>
#include <cstdint>

namespace clothcd::sim {
namespace {
constexpr int kGrain = 512;

/// Counting sort of (key, value) pairs into CSR, keeping the insertion order within a key.
void build_csr(int keys, const std::vector<std::pair<int, int>>& pairs, std::vector<int>& start,
               std::vector<int>& values) {
  start.assign(keys + 1, 0);
  for (const auto& [k, v] : pairs)
    ++start[k + 1];
  for (int k = 0; k < keys; ++k)
    start[k + 1] += start[k];
  values.resize(pairs.size());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (const auto& [k, v] : pairs)
    values[fill[k]++] = v;
}
}  // namespace

int BlockCsr::slot(int i, int j) const {
  const auto first = cols.begin() + row_start[i];
  const auto last = cols.begin() + row_start[i + 1];
  const auto it = std::lower_bound(first, last, j);
  assert(it != last && *it == j);
  return static_cast<int>(it - cols.begin());
}

SystemAssembler::SystemAssembler(const ClothModel& model) : model_(model) {
  const int n = model.num_vertices();
  const auto& faces = model.topology().faces();
  for (int f = 0; f < model.topology().num_faces(); ++f) {
    if (model.membrane_active()[f]) active_faces_.push_back(f);
  }
  // Pattern: every vertex pair that shares an element, plus the diagonal.
  std::vector<std::uint64_t> keys;
  auto add_clique = [&](std::span<const int> vs) {
    for (int a : vs) {
      for (int b : vs)
        keys.push_back(static_cast<std::uint64_t>(a) << 32 | static_cast<unsigned>(b));
    }
  };
  for (int v = 0; v < n; ++v)
    add_clique(std::array<int, 1>{v});
  for (int f : active_faces_)
    add_clique(faces[f]);
  for (const Hinge& h : model.hinges())
    add_clique(h.v);
  for (const StitchTerm& s : model.stitches())
    add_clique(std::span<const int>(s.v.data(), s.count));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  pattern_.row_start.assign(n + 1, 0);
  pattern_.cols.resize(keys.size());
  for (std::size_t k = 0; k < keys.size(); ++k) {
    ++pattern_.row_start[(keys[k] >> 32) + 1];
    pattern_.cols[k] = static_cast<int>(keys[k] & 0xffffffffu);
  }
  for (int i = 0; i < n; ++i)
    pattern_.row_start[i + 1] += pattern_.row_start[i];
  pattern_.diag.resize(n);
  for (int i = 0; i < n; ++i)
    pattern_.diag[i] = pattern_.slot(i, i);

  // Constant Hessians: bending K K^T (x) I and stitch w w^T (x) I, summed in element order.
  constant_.assign(keys.size(), Mat3::Zero());
  for (const Hinge& h : model.hinges()) {
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        constant_[pattern_.slot(h.v[a], h.v[b])].diagonal().array() +=
            h.w.scale * h.w.k[a] * h.w.k[b];
      }
    }
  }
  const double kst = model.material().stitch_stiffness;
  for (const StitchTerm& s : model.stitches()) {
    for (int a = 0; a < s.count; ++a) {
      for (int b = 0; b < s.count; ++b) {
        constant_[pattern_.slot(s.v[a], s.v[b])].diagonal().array() += kst * s.w[a] * s.w[b];
      }
    }
  }
  // Gather maps for the membrane.
  std::vector<std::pair<int, int>> slot_pairs, vert_pairs;
  const int na = static_cast<int>(active_faces_.size());
  slot_pairs.reserve(9 * na);
  vert_pairs.reserve(3 * na);
  for (int k = 0; k < na; ++k) {
    const Face& t = faces[active_faces_[k]];
    for (int i = 0; i < 3; ++i) {
      vert_pairs.emplace_back(t[i], 3 * k + i);
      for (int j = 0; j < 3; ++j)
        slot_pairs.emplace_back(pattern_.slot(t[i], t[j]), 9 * k + 3 * i + j);
    }
  }
  build_csr(static_cast<int>(keys.size()), slot_pairs, slot_src_start_, slot_src_);
  build_csr(n, vert_pairs, vert_src_start_, vert_src_);
  face_hess_.resize(9 * na);
  face_grad_.resize(3 * na);
  face_stretch_.resize(na);

  // The matrix handed out: slots no membrane reaches hold their constant part, a multiple of
  // the identity (checked), as a scalar; the diagonal stays a full block for the preconditioner.
  matrix_.row_start.assign(n + 1, 0);
  matrix_.scalar_row_start.assign(n + 1, 0);
  matrix_.diag.resize(n);
  for (int i = 0; i < n; ++i) {
    for (int q = pattern_.row_start[i]; q < pattern_.row_start[i + 1]; ++q) {
      const Mat3& c = constant_[q];
      const bool scalar = q != pattern_.diag[i] && slot_src_start_[q] == slot_src_start_[q + 1] &&
                          c == c(0, 0) * Mat3::Identity();
      if (scalar) {
        matrix_.scalar_cols.push_back(pattern_.cols[q]);
        matrix_.scalar_values.push_back(c(0, 0));
      } else {
        if (q == pattern_.diag[i]) matrix_.diag[i] = static_cast<int>(matrix_.cols.size());
        matrix_.cols.push_back(pattern_.cols[q]);
        general_slot_.push_back(q);
      }
    }
    matrix_.row_start[i + 1] = static_cast<int>(matrix_.cols.size());
    matrix_.scalar_row_start[i + 1] = static_cast<int>(matrix_.scalar_cols.size());
  }
  matrix_.values.assign(matrix_.cols.size(), Mat3::Zero());
}

BlockCsr SystemAssembler::make_matrix() const {
  return matrix_;
}

double SystemAssembler::assemble(std::span<const Vec3> x, BlockCsr& h, Vecs& gradient) {
  const auto& faces = model_.topology().faces();
  const int na = static_cast<int>(active_faces_.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, na, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) {
      const int f = active_faces_[k];
      const Face& t = faces[f];
      const MembraneEval e = membrane_eval({x[t[0]], x[t[1]], x[t[2]]}, model_.membrane_rest()[f],
                                           model_.moduli(), /*project_psd=*/true);
      for (int i = 0; i < 3; ++i) {
        face_grad_[3 * k + i] = e.gradient[i];
        for (int j = 0; j < 3; ++j)
          face_hess_[9 * k + 3 * i + j] = e.hessian[i][j];
      }
      face_stretch_[k] = e.max_stretch;
    }
  });
  if (h.values.size() != matrix_.values.size()) h = matrix_;
  const int blocks = static_cast<int>(general_slot_.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 4 * kGrain),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int b = r.begin(); b < r.end(); ++b) {
                        const int s = general_slot_[b];
                        Mat3 sum = constant_[s];
                        for (int q = slot_src_start_[s]; q < slot_src_start_[s + 1]; ++q) {
                          sum += face_hess_[slot_src_[q]];
                        }
                        h.values[b] = sum;
                      }
                    });
  // Gradient: membrane gathered per vertex, plus the constant part's H_c x.
  const int n = model_.num_vertices();
  gradient.resize(n);
  tbb::parallel_for(tbb::blocked_range<int>(0, n, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      Vec3 g = Vec3::Zero();
      for (int s = pattern_.row_start[i]; s < pattern_.row_start[i + 1]; ++s) {
        g += constant_[s] * x[pattern_.cols[s]];
      }
      for (int q = vert_src_start_[i]; q < vert_src_start_[i + 1]; ++q)
        g += face_grad_[vert_src_[q]];
      gradient[i] = g;
    }
  });
  double stretch = 0.0;
  for (double s : face_stretch_)
    stretch = std::max(stretch, s);
  return stretch;
}

double SystemAssembler::elastic_energy(std::span<const Vec3> x) const {
  const auto& faces = model_.topology().faces();
  double e = 0.0;
  for (int f : active_faces_) {
    const Face& t = faces[f];
    e +=
        membrane_eval({x[t[0]], x[t[1]], x[t[2]]}, model_.membrane_rest()[f], model_.moduli(), true)
            .energy;
  }
  for (const Hinge& h : model_.hinges()) {
    e += bending_energy(h.w, {x[h.v[0]], x[h.v[1]], x[h.v[2]], x[h.v[3]]});
  }
  const double kst = model_.material().stitch_stiffness;
  for (const StitchTerm& s : model_.stitches()) {
    Vec3 d = Vec3::Zero();
    for (int a = 0; a < s.count; ++a)
      d += s.w[a] * x[s.v[a]];
    e += 0.5 * kst * d.squaredNorm();
  }
  return e;
}

void multiply(const BlockCsr& a, std::span<const Vec3> x, std::span<Vec3> y) {
  tbb::parallel_for(tbb::blocked_range<int>(0, a.rows(), kGrain),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int i = r.begin(); i < r.end(); ++i)
                        y[i] = row_product(a, x, i);
                    });
}

double deterministic_sum(int n, const std::function<double(int, int)>& range_sum) {
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<int>(0, n, 1024), 0.0,
      [&](const tbb::blocked_range<int>& r, double acc) {
        return acc + range_sum(r.begin(), r.end());
      },
      [](double a, double b) { return a + b; });
}

}  // namespace clothcd::sim
