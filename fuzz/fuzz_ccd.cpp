// Fuzzes the vertex-face and edge-edge CCD kernels: no crash, no sanitizer report, never a NaN
// time, and the time of impact always in [0, 1].
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "clothcd/ccd/queries.hpp"
#include "fuzz_input.hpp"

namespace {

void check(const clothcd::CcdResult& r) {
  if (!(r.toi >= 0.0 && r.toi <= 1.0)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  clothcd::fuzz::ByteReader in(data, size);
  const int mode = in.byte();
  const bool raw = (mode & 1) != 0;  // raw bit patterns (NaN, inf, huge) or scaled finite values
  const double scale = std::pow(10.0, static_cast<int>(in.byte() % 41) - 20);
  Eigen::Vector3d p[8];
  for (auto& v : p) {
    for (int i = 0; i < 3; ++i) {
      v[i] = raw ? in.raw_double() : std::tanh(in.finite_double()) * scale;
    }
  }
  clothcd::CcdOptions opt;
  opt.thickness = (mode & 2) != 0 ? scale * (in.byte() / 255.0) * 1e-2 : 0.0;
  opt.fast_path = (mode & 4) == 0;
  try {
    check(clothcd::vertex_face_ccd({p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]}, opt));
    check(clothcd::edge_edge_ccd({p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]}, opt));
    (void)clothcd::np_filter_culls(
        clothcd::VertexFaceQuery{p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]});
    (void)clothcd::np_filter_culls(
        clothcd::EdgeEdgeQuery{p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]});
  } catch (const std::invalid_argument&) {
    // NaN/inf input is rejected by contract.
  }
  return 0;
}
