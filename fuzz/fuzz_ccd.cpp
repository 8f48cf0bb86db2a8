// Fuzzes the vertex-face and edge-edge CCD kernels: no crash, no sanitizer report, never a NaN
// time, and the time of impact always in [0, 1]. At zero thickness also the vector NP filter and
// fast path (np_batch.hpp) on the same query: every instruction set the processor has gives the
// scalar reference's verdicts and answers, and each settled answer is the kernel's own.
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "ccd/np_batch.hpp"
#include "clothcd/ccd/queries.hpp"
#include "fuzz_input.hpp"

namespace {

using clothcd::ccd_detail::FastSettled;
using clothcd::ccd_detail::Kind;
using clothcd::ccd_detail::NpBatch;
using clothcd::ccd_detail::NpVerdict;

void check(const clothcd::CcdResult& r) {
  if (!(r.toi >= 0.0 && r.toi <= 1.0)) std::abort();
}

// The query as a batch of one, through every instruction set; `kernel` runs the kernel on it
// with the NP verdict known to be Kept.
template <class Kernel>
void check_batch(Kind kind, const Eigen::Vector3d (&p)[8], const clothcd::CcdOptions& opt,
                 Kernel&& kernel) {
  NpBatch b;
  b.push({p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data(), p[5].data(), p[6].data(),
          p[7].data()});
  NpVerdict verdict[1], v[1];
  FastSettled settled[1], s[1];
  double toi[1], t[1];
  if (!clothcd::ccd_detail::np_filter_batch_with(0, kind, b, verdict)) std::abort();
  if (!clothcd::ccd_detail::fast_path_settle_with(0, kind, b, verdict, opt.toi_tolerance, settled,
                                                  toi)) {
    std::abort();
  }
  for (int isa = 1; isa <= 3; ++isa) {
    if (!clothcd::ccd_detail::np_filter_batch_with(isa, kind, b, v)) continue;
    if (v[0] != verdict[0]) std::abort();
    if (!clothcd::ccd_detail::fast_path_settle_with(isa, kind, b, verdict, opt.toi_tolerance, s,
                                                    t)) {
      std::abort();
    }
    if (s[0] != settled[0] || (s[0] == FastSettled::Hit && t[0] != toi[0])) std::abort();
  }
  if (settled[0] == FastSettled::Run) return;
  if (verdict[0] != NpVerdict::Kept) std::abort();
  const clothcd::CcdResult r = kernel();
  if (settled[0] == FastSettled::Miss && (r.hit || r.path != clothcd::CcdPath::FastPath)) {
    std::abort();
  }
  if (settled[0] == FastSettled::Hit &&
      (!r.hit || r.path != clothcd::CcdPath::Certified || r.toi != toi[0])) {
    std::abort();
  }
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
    if (opt.thickness == 0) {
      clothcd::CcdOptions fast = opt;
      fast.fast_path = true;
      check_batch(Kind::VertexFace, p, fast, [&] {
        return clothcd::ccd_detail::vertex_face_ccd_np_kept(
            {p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]}, fast);
      });
      check_batch(Kind::EdgeEdge, p, fast, [&] {
        return clothcd::ccd_detail::edge_edge_ccd_np_kept(
            {p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]}, fast);
      });
    }
  } catch (const std::invalid_argument&) {
    // NaN/inf input is rejected by contract.
  }
  return 0;
}
