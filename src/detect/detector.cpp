// The self-collision detector along its data flow: the options checked, then each detect()
// refits the tree (boxes, and cones where the culling needs them), traverses it under the culling
// rule (self_traverse.cpp), runs the narrow phase over the triangle pairs and the orphans
// (self_narrow.cpp) and finishes (sorted results, the pairs kept for reuse). proximity() is in
// self_proximity.cpp, the state they share in self_core.hpp.

#include "clothcd/detect/detector.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <string_view>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "bvh/optimal_cones.hpp"
#include "clothcd/core/error.hpp"
#include "clothcd/detect/names.hpp"
#include "detect/options.hpp"
#include "detect/self_core.hpp"

namespace clothcd {
namespace detail {

namespace {
// A build's temporaries (the tree's and the topology's, many freed by worker threads) leave free
// memory in the allocator's arenas, which the process keeps resident: about 330 MB after a build
// on 4M triangles, beside the detector's 1.4 GB. Returned to the system once the build is done.
void return_free_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}
}  // namespace

void check_self_options(const DetectOptions& o) {
  check_common_options(o);
  if (!(o.reuse_distance >= 0) || !std::isfinite(o.reuse_distance)) {
    throw InputError(
        fmt::format("reuse distance must be finite and >= 0, got {}", o.reuse_distance));
  }
  if (o.cull_min_triangles < 0) {
    throw InputError(fmt::format("cull_min_triangles must be >= 0, got {}", o.cull_min_triangles));
  }
}

void check_same_build(BvhBuild built, BvhBuild asked, std::string_view call) {
  if (asked != built) {
    throw InputError(fmt::format(
        "{}: the BVH build is fixed at construction ({}), got {}; construct a detector for "
        "another build",
        call, to_string(built), to_string(asked)));
  }
}

SelfCore::SelfCore(std::vector<Face> faces, int nv, PointsIn ref, const DetectOptions& o)
    : MeshState((check_self_options(o), std::move(faces)), nv, ref, "reference shape", o.build,
                true, true),
      opt(o) {
  cull = o.culling == Culling::Sound ? Rule::Sound : Rule::None;
  orphans = find_orphans(topo);
  owner = Ownership(topo);
  return_free_memory();
}

void SelfCore::set_options(const DetectOptions& o) {
  check_self_options(o);
  check_same_build(opt.build, o.build, "set_options");
  opt = o;
  cull = o.culling == Culling::Sound ? Rule::Sound : Rule::None;
  optimal_cones = false;
  links_current = false;
  reuse.valid = false;
  if (!o.reuse_front) front.clear();
}

void SelfCore::refit(DetectStats& st) {
  const auto t = Clock::now();
  RefitOptions ro;
  ro.thickness = box_reach();
  ro.cones = cones_used(rule());
  ro.policy = opt.policy;
  // The unsound rules are measured on every node.
  if (rule() == Rule::Sound) ro.cone_min_triangles = opt.cull_min_triangles;
  const auto moved = step.changed_since(bvh_call);
  if (optimal_cones) {
    OptimalCones::refit_moved(bvh, v0, v1, ro, moved);
  } else {
    bvh.refit_moved(v0, v1, ro, moved);
  }
  bvh_call = step.call();
  st.time_refit = seconds_since(t);
  st.internal_nodes = bvh.num_internal();
  st.connected_internal_nodes = bvh.num_connected_internal();
  st.disk_internal_nodes = bvh.num_disk_internal();
}

DetectResult SelfCore::detect(PointsIn p0, PointsIn p1, bool kernels) {
  step.update(p0, p1, topo.num_vertices(), "positions at t0", "positions at t1");
  update_links();
  DetectResult res;
  DetectStats& st = res.stats;
  refit(st);
  // The boxes first: the narrow phase then follows the traversal a round of pairs at a time
  // (traverse_each).
  auto t = Clock::now();
  FeatureContext ctx = ccd_context();
  ctx.plan.kernel = kernels;
  boxes.update(ctx, step);
  double narrow_s = seconds_since(t);
  const bool keep = keeps() && !restricted;
  if (keep) {
    reuse.valid = false;  // until every round's pairs are in
    reuse.pairs.clear();
  }
  std::vector<std::uint8_t> near;
  NarrowLocals locals;
  traverse_each(rule(), scope(), st, pair_locals, opt.reuse_front && !restricted,
                [&](const PairList& pairs) {
                  const auto t0 = Clock::now();
                  narrow_pairs(ctx, pairs, scope(), locals, keep ? &near : nullptr);
                  narrow_s += seconds_since(t0);
                  if (!keep) return;
                  pairs.for_each([&](std::size_t i, const FacePair& p) {
                    if (near[i] != 0) reuse.pairs.push_back(p);
                  });
                });
  t = Clock::now();
  narrow_orphans(ctx, scope(), locals);
  st.triangle_pairs = 0;
  gather(locals, res);
  finish(res);
  st.time_narrow = narrow_s + seconds_since(t);
  if (keep) {
    reuse.x1 = v1;
    reuse.valid = true;
  }
  return res;
}

}  // namespace detail

namespace {
// SelfDetector::rebuild for either input form.
void rebuild_detector(detail::SelfCore& im, detail::PointsIn reference) {
  im.rebuild(reference, "reference shape", im.opt.build, true);
  im.front.clear();  // the front's node pairs belonged to the old tree
  detail::return_free_memory();
}
}  // namespace

SelfDetector::SelfDetector(std::vector<Face> faces, int num_vertices, const Positions& reference,
                           const DetectOptions& options)
    : impl_(
          std::make_unique<detail::SelfCore>(std::move(faces), num_vertices, reference, options)) {}
SelfDetector::SelfDetector(std::vector<Face> faces, int num_vertices,
                           std::span<const Eigen::Vector3d> reference, const DetectOptions& options)
    : impl_(
          std::make_unique<detail::SelfCore>(std::move(faces), num_vertices, reference, options)) {}
SelfDetector::SelfDetector(const Eigen::Ref<const Eigen::MatrixX3i>& faces,
                           const Positions& reference, const DetectOptions& options)
    : impl_(std::make_unique<detail::SelfCore>(to_faces(faces), static_cast<int>(reference.rows()),
                                               reference, options)) {}
SelfDetector::~SelfDetector() = default;
SelfDetector::SelfDetector(SelfDetector&&) noexcept = default;
SelfDetector& SelfDetector::operator=(SelfDetector&&) noexcept = default;

DetectResult SelfDetector::detect(const Positions& v_t0, const Positions& v_t1) {
  return impl_->detect(v_t0, v_t1);
}
DetectResult SelfDetector::detect(std::span<const Eigen::Vector3d> v_t0,
                                  std::span<const Eigen::Vector3d> v_t1) {
  return impl_->detect(v_t0, v_t1);
}
ProximityResult SelfDetector::proximity(const Positions& v, double h) {
  return impl_->proximity(v, h);
}
ProximityResult SelfDetector::proximity(std::span<const Eigen::Vector3d> v, double h) {
  return impl_->proximity(v, h);
}
EarliestImpact SelfDetector::earliest_impact(const Positions& v_t0, const Positions& v_t1,
                                             const EarliestOptions& options) {
  return impl_->earliest_impact(v_t0, v_t1, options);
}
EarliestImpact SelfDetector::earliest_impact(std::span<const Eigen::Vector3d> v_t0,
                                             std::span<const Eigen::Vector3d> v_t1,
                                             const EarliestOptions& options) {
  return impl_->earliest_impact(v_t0, v_t1, options);
}
void SelfDetector::set_active_faces(std::span<const int> faces) {
  impl_->set_active_faces(faces);
}
void SelfDetector::set_active_vertices(std::span<const int> vertices) {
  impl_->set_active_vertices(vertices, "");
}
void SelfDetector::clear_active() {
  impl_->clear_active();
}
void SelfDetector::rebuild(const Positions& reference) {
  rebuild_detector(*impl_, reference);
}
void SelfDetector::rebuild(std::span<const Eigen::Vector3d> reference) {
  rebuild_detector(*impl_, reference);
}
const DetectOptions& SelfDetector::options() const {
  return impl_->opt;
}
void SelfDetector::set_options(const DetectOptions& options) {
  impl_->set_options(options);
}
const Topology& SelfDetector::topology() const {
  return impl_->topo;
}
const Bvh& SelfDetector::bvh() const {
  return impl_->bvh;
}

}  // namespace clothcd
