#pragma once
// The implicit system's sparse matrix: 3x3 blocks in a CSR pattern fixed once from the cloth's
// elements, filled by a gather (every slot sums its contributions in a fixed order), so assembly
// is parallel and bitwise independent of the thread count.

#include <functional>
#include <span>
#include <vector>

#include "clothcd/sim/cloth_model.hpp"

namespace clothcd::sim {

using Vecs = std::vector<Vec3>;

/// Symmetric block matrix in CSR form (both triangles stored). Blocks that are a constant
/// multiple of the identity (only bending and stitch terms reach them, as between the vertices
/// opposite a hinge: a large share of a garment's blocks) may be kept apart as one scalar each, so
/// that a product reads 8 bytes for them instead of 72.
struct BlockCsr {
  std::vector<int> row_start;  ///< size n + 1
  std::vector<int> cols;       ///< block column of each slot, ascending per row
  std::vector<int> diag;       ///< slot of (i, i)
  std::vector<Mat3> values;
  std::vector<int> scalar_row_start;  ///< size n + 1, or empty when there are none
  std::vector<int> scalar_cols;       ///< ascending per row
  std::vector<double> scalar_values;  ///< block = scalar_values[q] * I

  [[nodiscard]] int rows() const { return static_cast<int>(row_start.size()) - 1; }
  /// Slot of block (i, j); the block must be in the pattern.
  [[nodiscard]] int slot(int i, int j) const;
};

/// Assembles the membrane Hessian and gradient plus the constant bending and stitch terms.
class SystemAssembler {
 public:
  explicit SystemAssembler(const ClothModel& model);

  /// H = membrane (PSD-projected) + constant part, and the full gradient of the elastic energy at
  /// x. Returns the largest membrane stretch at x.
  double assemble(std::span<const Vec3> x, BlockCsr& h, Vecs& gradient);

  /// An empty matrix with the pattern (values zero).
  [[nodiscard]] BlockCsr make_matrix() const;

  /// Total elastic energy at x (membrane + bending + stitches).
  [[nodiscard]] double elastic_energy(std::span<const Vec3> x) const;

 private:
  const ClothModel& model_;
  BlockCsr pattern_;               // every slot (no values)
  BlockCsr matrix_;                // the split form make_matrix() hands out
  std::vector<int> general_slot_;  // per full block of matrix_: its slot in pattern_
  std::vector<int> active_faces_;
  std::vector<Mat3> constant_;       // bending + stitch Hessian, per slot
  std::vector<int> slot_src_start_;  // per slot: range into slot_src_
  std::vector<int> slot_src_;        // index into face Hessian buffer (face * 9 + i * 3 + j)
  std::vector<int> vert_src_start_;  // per vertex: range into vert_src_
  std::vector<int> vert_src_;        // index into face gradient buffer (face * 3 + i)
  std::vector<Mat3> face_hess_;
  std::vector<Vec3> face_grad_;
  std::vector<double> face_stretch_;
};

/// (A x)_i: the full blocks of row i in column order, then the scalar ones.
inline Vec3 row_product(const BlockCsr& a, std::span<const Vec3> x, int i) {
  Vec3 s = Vec3::Zero();
  for (int q = a.row_start[i]; q < a.row_start[i + 1]; ++q)
    s += a.values[q] * x[a.cols[q]];
  if (!a.scalar_row_start.empty()) {
    for (int q = a.scalar_row_start[i]; q < a.scalar_row_start[i + 1]; ++q)
      s += a.scalar_values[q] * x[a.scalar_cols[q]];
  }
  return s;
}

/// y = A x for a block matrix (parallel over rows, each row as row_product).
void multiply(const BlockCsr& a, std::span<const Vec3> x, std::span<Vec3> y);

/// Sum over i of f(i) with a split tree fixed by n alone: bitwise equal for any thread count.
double deterministic_sum(int n, const std::function<double(int, int)>& range_sum);

}  // namespace clothcd::sim
