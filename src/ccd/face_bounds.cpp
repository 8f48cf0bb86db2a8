// Distance bounds of whole triangles (face_bounds.hpp): the scalar instance of
// face_bounds_impl.hpp, which the batched filter (face_batch.hpp) repeats lane by lane.
#include "ccd/face_bounds.hpp"

#define FACE_BOUNDS_NAMESPACE scalar_impl
#include "ccd/face_bounds_impl.hpp"

namespace clothcd::ccd_detail {
namespace {

using P = scalar_impl::P3<double>;
using Tri = scalar_impl::Tri<double>;

void load(const Triangle& t, Tri& out) {
  for (int k = 0; k < 3; ++k)
    out[k] = P{(*t[k])[0], (*t[k])[1], (*t[k])[2]};
}

}  // namespace

double triangle_triangle_bound(const Triangle& a, const Triangle& b) {
  Tri ta, tb;
  load(a, ta);
  load(b, tb);
  return scalar_impl::triangle_triangle_bound(ta, tb);
}

bool triangles_filter_culls(const Triangle& a_t0, const Triangle& a_t1, const Triangle& b_t0,
                            const Triangle& b_t1, double thickness, double* bound_t1) {
  Tri a0, a1, b0, b1;
  load(a_t0, a0);
  load(a_t1, a1);
  load(b_t0, b0);
  load(b_t1, b1);
  double d1 = 0.0;
  const bool culls = scalar_impl::triangles_filter(a0, a1, b0, b1, thickness, d1);
  if (bound_t1 != nullptr) *bound_t1 = d1;
  return culls;
}

}  // namespace clothcd::ccd_detail
