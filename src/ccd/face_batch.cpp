// The batched whole-triangle filters: the widest body the processor runs (face_batch_*.cpp), or
// the scalar filter pair by pair without xsimd or off x86-64 (CLOTHCD_SIMD_X86 unset).
#include "ccd/face_batch.hpp"

#include "core/isa.hpp"

namespace clothcd::ccd_detail {

#if CLOTHCD_SIMD_X86
void triangles_filter_batch_sse2(const FacePairBatch& b, double thickness, bool* culls,
                                 double* bound_t1);
void triangles_filter_batch_avx2(const FacePairBatch& b, double thickness, bool* culls,
                                 double* bound_t1);
void triangles_filter_batch_avx512(const FacePairBatch& b, double thickness, bool* culls,
                                   double* bound_t1);
void triangle_bound_batch_sse2(const StaticFacePairBatch& b, double* bound);
void triangle_bound_batch_avx2(const StaticFacePairBatch& b, double* bound);
void triangle_bound_batch_avx512(const StaticFacePairBatch& b, double* bound);
#endif

namespace {

void triangles_filter_batch_scalar(const FacePairBatch& b, double thickness, bool* culls,
                                   double* bound_t1) {
  for (int i = 0; i < b.size; ++i) {
    Eigen::Vector3d p[12];
    for (int k = 0; k < 12; ++k)
      p[k] = {b.x[3 * k][i], b.x[3 * k + 1][i], b.x[3 * k + 2][i]};
    culls[i] =
        triangles_filter_culls({&p[0], &p[1], &p[2]}, {&p[3], &p[4], &p[5]}, {&p[6], &p[7], &p[8]},
                               {&p[9], &p[10], &p[11]}, thickness, &bound_t1[i]);
  }
}

void triangle_bound_batch_scalar(const StaticFacePairBatch& b, double* bound) {
  for (int i = 0; i < b.size; ++i) {
    Eigen::Vector3d p[6];
    for (int k = 0; k < 6; ++k)
      p[k] = {b.x[3 * k][i], b.x[3 * k + 1][i], b.x[3 * k + 2][i]};
    bound[i] = triangle_triangle_bound({&p[0], &p[1], &p[2]}, {&p[3], &p[4], &p[5]});
  }
}

#if CLOTHCD_SIMD_X86
constexpr void (*const kFilter[4])(const FacePairBatch&, double, bool*, double*) = {
    triangles_filter_batch_scalar, triangles_filter_batch_sse2, triangles_filter_batch_avx2,
    triangles_filter_batch_avx512};
constexpr void (*const kBound[4])(const StaticFacePairBatch&, double*) = {
    triangle_bound_batch_scalar, triangle_bound_batch_sse2, triangle_bound_batch_avx2,
    triangle_bound_batch_avx512};
#else
constexpr void (*const kFilter[4])(const FacePairBatch&, double, bool*, double*) = {
    triangles_filter_batch_scalar, nullptr, nullptr, nullptr};
constexpr void (*const kBound[4])(const StaticFacePairBatch&, double*) = {
    triangle_bound_batch_scalar, nullptr, nullptr, nullptr};
#endif

}  // namespace

void triangles_filter_batch(const FacePairBatch& b, double thickness, bool* culls,
                            double* bound_t1) {
  simd::run_on(-1, kFilter, b, thickness, culls, bound_t1);
}

bool triangles_filter_batch_with(int isa, const FacePairBatch& b, double thickness, bool* culls,
                                 double* bound_t1) {
  return isa >= 0 && simd::run_on(isa, kFilter, b, thickness, culls, bound_t1);
}

void triangle_bound_batch(const StaticFacePairBatch& b, double* bound) {
  simd::run_on(-1, kBound, b, bound);
}

bool triangle_bound_batch_with(int isa, const StaticFacePairBatch& b, double* bound) {
  return isa >= 0 && simd::run_on(isa, kBound, b, bound);
}

}  // namespace clothcd::ccd_detail
