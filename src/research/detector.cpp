// research::SelfDetector: the product's self detector with the research options on its core,
// and the verification pass that runs the unculled traversal and narrow phase on the same step.

#include "clothcd/research/detector.hpp"

#include <algorithm>
#include <iterator>

#include "clothcd/core/error.hpp"
#include "clothcd/research/names.hpp"
#include "research/core_options.hpp"

namespace clothcd::research {

void check_research(const DetectOptions& o) {
  if (o.reuse_distance > 0 && unsound(culling_rule(o))) {
    throw InputError(
        "reuse distance: the unsound culling rules may cull the pairs it keeps; use culling none "
        "or sound with it");
  }
}

void use(detail::SelfCore& core, const DetectOptions& o) {
  core.opt = o;
  switch (culling_rule(o)) {
    case CullingRule::None:
      core.cull = detail::CullRule::None;
      break;
    case CullingRule::Cone:
      core.cull = detail::CullRule::Cone;
      break;
    case CullingRule::Gated:
      core.cull = detail::CullRule::Gated;
      break;
    case CullingRule::Sound:
      core.cull = detail::CullRule::Sound;
      break;
  }
  core.optimal_cones = o.research.optimal_cones;
}

namespace {

const DetectOptions& checked(const DetectOptions& o) {
  check_research(o);
  return o;
}

// The unculled detection of the step the core just detected (its boxes are up to date), and what
// `res` lacks of it.
void verify(detail::SelfCore& core, DetectResult& res) {
  clothcd::DetectResult ref;
  detail::PairLocals all_locals;
  const detail::PairList all =
      core.traverse(detail::CullRule::None, core.scope(), ref.stats, all_locals);
  detail::FeatureContext ctx = core.ccd_context();
  core.boxes.update(ctx, core.step);
  core.narrow(ctx, all, core.scope(), ref);
  Verification& ver = res.verification;
  ver.ran = true;
  ver.unculled_triangle_pairs = all.size();
  std::set_difference(ref.vf.begin(), ref.vf.end(), res.vf.begin(), res.vf.end(),
                      std::back_inserter(ver.missed_vf), detail::vf_less);
  std::set_difference(ref.ee.begin(), ref.ee.end(), res.ee.begin(), res.ee.end(),
                      std::back_inserter(ver.missed_ee), detail::ee_less);
}

}  // namespace

SelfDetector::SelfDetector(std::vector<Face> faces, int num_vertices, const Positions& reference,
                           const DetectOptions& options)
    : clothcd::SelfDetector(std::move(faces), num_vertices, reference, checked(options)),
      options_(options) {
  use(detail::SelfAccess::core(*this), options_);
}
SelfDetector::SelfDetector(std::vector<Face> faces, int num_vertices,
                           std::span<const Eigen::Vector3d> reference, const DetectOptions& options)
    : clothcd::SelfDetector(std::move(faces), num_vertices, reference, checked(options)),
      options_(options) {
  use(detail::SelfAccess::core(*this), options_);
}
SelfDetector::SelfDetector(const Eigen::Ref<const Eigen::MatrixX3i>& faces,
                           const Positions& reference, const DetectOptions& options)
    : clothcd::SelfDetector(faces, reference, checked(options)), options_(options) {
  use(detail::SelfAccess::core(*this), options_);
}

namespace {
template <class P>
DetectResult detect_with(SelfDetector& d, const DetectOptions& o, const P& p0, const P& p1) {
  DetectResult res;
  static_cast<clothcd::DetectResult&>(res) = d.clothcd::SelfDetector::detect(p0, p1);
  detail::SelfCore& core = detail::SelfAccess::core(d);
  if (o.research.verify && core.cull != detail::CullRule::None) verify(core, res);
  return res;
}
}  // namespace

DetectResult SelfDetector::detect(const Positions& v_t0, const Positions& v_t1) {
  return detect_with(*this, options_, v_t0, v_t1);
}
DetectResult SelfDetector::detect(std::span<const Eigen::Vector3d> v_t0,
                                  std::span<const Eigen::Vector3d> v_t1) {
  return detect_with(*this, options_, v_t0, v_t1);
}

std::vector<clothcd::DetectResult> SelfDetector::detect_each(
    const Positions& v_t0, const Positions& v_t1, std::span<const DetectOptions> configs) {
  return detect_each_on(detail::SelfAccess::core(*this), v_t0, v_t1, configs);
}
std::vector<clothcd::DetectResult> SelfDetector::detect_each(
    std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
    std::span<const DetectOptions> configs) {
  return detect_each_on(detail::SelfAccess::core(*this), v_t0, v_t1, configs);
}

void SelfDetector::set_options(const DetectOptions& options) {
  check_research(options);
  clothcd::SelfDetector::set_options(options);
  options_ = options;
  use(detail::SelfAccess::core(*this), options_);
}

}  // namespace clothcd::research
