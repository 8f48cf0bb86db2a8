#pragma once
// Internal: triangles_filter_culls (face_bounds.hpp) over a batch of triangle pairs held as a
// structure of arrays, several pairs per vector instruction. Each lane performs the scalar
// filter's floating-point operations in its order (face_bounds_impl.hpp), so every verdict and
// every bound is the scalar one, bit for bit.

#include <Eigen/Core>

#include "ccd/face_bounds.hpp"

namespace clothcd::ccd_detail {

/// Up to kCapacity entries of `Triangles` triangles each, gathered coordinate by coordinate for the
/// batched filters: coordinate c (0..2) of point p of entry i is x[3 * p + c][i], the points
/// being the triangles' corners in the order pushed.
template <int Triangles>
struct TriangleBatch {
  static constexpr int kCapacity = 64;  // a multiple of every vector width
  alignas(64) double x[9 * Triangles][kCapacity] = {};
  int size = 0;

  template <class... T>
  void push(const T&... triangles) {
    static_assert(sizeof...(T) == Triangles);
    int p = 0;
    for (const Triangle* t : {&triangles...}) {
      for (const Eigen::Vector3d* q : *t) {
        for (int c = 0; c < 3; ++c)
          x[3 * p + c][size] = (*q)[c];
        ++p;
      }
    }
    ++size;
  }
};

/// Triangle pairs moving over a step, for triangles_filter_batch: a at t0, a at t1, b at t0, b at
/// t1 (points 0..2, 3..5, 6..8, 9..11).
using FacePairBatch = TriangleBatch<4>;
/// Triangle pairs at one time, for triangle_bound_batch: a, then b (points 0..2, 3..5).
using StaticFacePairBatch = TriangleBatch<2>;

/// For each pair i < b.size: culls[i] = triangles_filter_culls(a_t0, a_t1, b_t0, b_t1, thickness,
/// &bound_t1[i]). Uses the widest vector instructions the processor has (AVX-512, AVX2 or the
/// SSE2 baseline).
void triangles_filter_batch(const FacePairBatch& b, double thickness, bool* culls,
                            double* bound_t1);

/// The same with a fixed instruction set, for tests: 0 scalar (triangles_filter_culls per pair),
/// 1 SSE2, 2 AVX2, 3 AVX-512F. Returns false (and does nothing) when the processor lacks it.
bool triangles_filter_batch_with(int isa, const FacePairBatch& b, double thickness, bool* culls,
                                 double* bound_t1);

/// For each pair i < b.size: bound[i] = triangle_triangle_bound(a, b), as
/// triangles_filter_batch does it (the widest vector instructions there are).
void triangle_bound_batch(const StaticFacePairBatch& b, double* bound);

/// The same with a fixed instruction set, for tests (as triangles_filter_batch_with).
bool triangle_bound_batch_with(int isa, const StaticFacePairBatch& b, double* bound);

}  // namespace clothcd::ccd_detail
