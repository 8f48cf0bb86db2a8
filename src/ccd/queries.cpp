// The public CCD kernels: validation, rescaling, then the fast path (zero thickness) or the
// inclusion solver. Soundness of the combination: a zero-thickness contact needs the four points
// coplanar, i.e. a root of the exact coplanarity cubic, with the contact point in the features;
// the fast path drops only time ranges on which that cubic provably has no root or the point is
// provably outside, certifies a hit only where both provably hold, and hands every other range to
// the inclusion solver.

#include "clothcd/ccd/queries.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "ccd/cubic.hpp"
#include "ccd/fast_path.hpp"
#include "ccd/inclusion.hpp"
#include "ccd/motion.hpp"
#include "ccd/np_batch.hpp"
#include "ccd/refine.hpp"

namespace clothcd {

namespace {

using ccd_detail::Kind;
using ccd_detail::Motion;

void check_options(const CcdOptions& opt) {
  if (!(opt.thickness >= 0) || !std::isfinite(opt.thickness)) {
    throw std::invalid_argument(
        fmt::format("CCD thickness must be finite and >= 0, got {}", opt.thickness));
  }
  if (!(opt.toi_tolerance >= 0) || !std::isfinite(opt.toi_tolerance)) {
    throw std::invalid_argument(
        fmt::format("CCD toi_tolerance must be finite and >= 0, got {}", opt.toi_tolerance));
  }
  if (!(opt.tolerance > 0) || !std::isfinite(opt.tolerance)) {
    throw std::invalid_argument(
        fmt::format("CCD tolerance must be finite and > 0, got {}", opt.tolerance));
  }
}

CcdResult from(const ccd_detail::InclusionOutcome& o, CcdPath path, std::uint32_t boxes) {
  CcdResult r;
  r.hit = o.hit;
  r.toi = o.hit ? o.toi : 1.0;
  r.u = o.u;
  r.v = o.v;
  r.path = path;
  r.boxes = boxes;
  return r;
}

// `np_kept`: the caller has found unscaled_np_filter's verdict Kept already.
CcdResult run(Kind kind, const std::array<const Eigen::Vector3d*, 8>& points, const CcdOptions& opt,
              bool np_kept = false) {
  check_options(opt);
  // Most pairs of a detection step end here: the NP filter without building the scaled motion.
  if (opt.fast_path && opt.thickness == 0 && !np_kept &&
      ccd_detail::unscaled_np_filter(kind, points) == ccd_detail::NpVerdict::Culled) {
    CcdResult r;
    r.path = CcdPath::NpCulled;
    return r;
  }
  const Motion m = ccd_detail::make_motion(points);
  const double max_coord = m.largest;
  // Any two of the points are within 2 sqrt(3) max|x| < 4 max|x|: contact from the start. This
  // also keeps the scaled thickness finite.
  if (opt.thickness >= 4 * max_coord) {
    CcdResult r;
    r.hit = true;
    r.toi = 0;
    return r;
  }
  ccd_detail::InclusionParams p;
  p.thickness = m.scale > 0 ? opt.thickness * m.scale : std::ldexp(opt.thickness, m.scale_exponent);
  p.tolerance = opt.tolerance * m.extent;
  p.toi_tolerance = opt.toi_tolerance;
  p.max_boxes = opt.max_boxes;

  if (opt.fast_path && opt.thickness == 0) {
    const ccd_detail::BernsteinCubic cubic = ccd_detail::coplanarity_cubic(kind, m);
    if (ccd_detail::np_culls(cubic)) {
      CcdResult r;
      r.path = CcdPath::NpCulled;
      return r;
    }
    const ccd_detail::FastOutcome o = ccd_detail::fast_path_solve(kind, m, cubic, p);
    CcdResult r;
    r.hit = o.hit;
    r.toi = o.hit ? o.toi : 1.0;
    r.u = o.u;
    r.v = o.v;
    r.path = o.certified ? CcdPath::Certified : CcdPath::FastPath;
    r.boxes = o.boxes;
    return r;
  }
  const auto o = ccd_detail::bounded_inclusion_solve(kind, m, p);
  return from(o, CcdPath::Inclusion, o.boxes);
}

std::array<const Eigen::Vector3d*, 8> points_of(const VertexFaceQuery& q) {
  return {&q.v_t0, &q.f0_t0, &q.f1_t0, &q.f2_t0, &q.v_t1, &q.f0_t1, &q.f1_t1, &q.f2_t1};
}
std::array<const Eigen::Vector3d*, 8> points_of(const EdgeEdgeQuery& q) {
  return {&q.ea0_t0, &q.ea1_t0, &q.eb0_t0, &q.eb1_t0, &q.ea0_t1, &q.ea1_t1, &q.eb0_t1, &q.eb1_t1};
}

}  // namespace

CcdResult vertex_face_ccd(const VertexFaceQuery& q, const CcdOptions& opt) {
  return run(Kind::VertexFace, points_of(q), opt);
}

CcdResult edge_edge_ccd(const EdgeEdgeQuery& q, const CcdOptions& opt) {
  return run(Kind::EdgeEdge, points_of(q), opt);
}

namespace ccd_detail {

CcdResult vertex_face_ccd_np_kept(const VertexFaceQuery& q, const CcdOptions& opt) {
  return run(Kind::VertexFace, points_of(q), opt, true);
}

CcdResult edge_edge_ccd_np_kept(const EdgeEdgeQuery& q, const CcdOptions& opt) {
  return run(Kind::EdgeEdge, points_of(q), opt, true);
}

}  // namespace ccd_detail

bool np_filter_culls(const VertexFaceQuery& q) {
  const auto verdict = ccd_detail::unscaled_np_filter(Kind::VertexFace, points_of(q));
  if (verdict != ccd_detail::NpVerdict::Undecided) return verdict == ccd_detail::NpVerdict::Culled;
  return ccd_detail::np_culls(
      ccd_detail::coplanarity_cubic(Kind::VertexFace, ccd_detail::make_motion(points_of(q))));
}

bool np_filter_culls(const EdgeEdgeQuery& q) {
  const auto verdict = ccd_detail::unscaled_np_filter(Kind::EdgeEdge, points_of(q));
  if (verdict != ccd_detail::NpVerdict::Undecided) return verdict == ccd_detail::NpVerdict::Culled;
  return ccd_detail::np_culls(
      ccd_detail::coplanarity_cubic(Kind::EdgeEdge, ccd_detail::make_motion(points_of(q))));
}

}  // namespace clothcd
