#pragma once
/// @file
/// The self detector with the research options (clothcd/research/options.hpp): the paper's
/// unsound culling rules, the optimal reference cones, verification against unculled detection,
/// and many configurations of one step at once (detect_each). It runs clothcd::SelfDetector's
/// stages (the same refit, traversal, narrow phase and results); with default research options it
/// reports what clothcd::SelfDetector reports.

#include <span>
#include <vector>

#include "clothcd/detect/detector.hpp"
#include "clothcd/research/options.hpp"

namespace clothcd::research {

class SelfDetector : public clothcd::SelfDetector {
 public:
  /// As clothcd::SelfDetector's constructors; also throws InputError for research options it
  /// cannot honour (an unsound rule with a reuse distance).
  SelfDetector(std::vector<Face> faces, int num_vertices, const Positions& reference,
               const DetectOptions& options = {});
  SelfDetector(std::vector<Face> faces, int num_vertices,
               std::span<const Eigen::Vector3d> reference, const DetectOptions& options = {});
  SelfDetector(const Eigen::Ref<const Eigen::MatrixX3i>& faces, const Positions& reference,
               const DetectOptions& options = {});

  /// clothcd::SelfDetector::detect under the research options; with Options::verify and a culling
  /// rule, also the unculled detection of the same step, and what the culled one missed in
  /// DetectResult::verification (the step then costs about both detections).
  [[nodiscard]] DetectResult detect(const Positions& v_t0, const Positions& v_t1);
  [[nodiscard]] DetectResult detect(std::span<const Eigen::Vector3d> v_t0,
                                    std::span<const Eigen::Vector3d> v_t1);

  /// The step v_t0 -> v_t1 under each of several options, for measuring culling rules and cone
  /// policies against each other (the experiment's counting pass). Result k holds what
  /// set_options(configs[k]) followed by detect() reports: the same collisions and the same
  /// counters of DetectStats. The work differs: every configuration refits its cones and walks
  /// its culling rule over the nodes, but the node pairs' box tests and the narrow phase run
  /// once, over the pairs that some configuration keeps, each pair's results counted for the
  /// configurations that keep it. time_refit is each configuration's own refit; time_traverse
  /// and time_narrow are NaN (shared work; detect() measures them). The configurations may
  /// differ only in policy, culling, cull_min_triangles and the research options'
  /// culling and optimal_cones; reuse_distance must be 0, verify off, the build the
  /// detector's, at most 64 of them and no active restriction. Throws InputError otherwise. The
  /// detector's own options are left as they were.
  [[nodiscard]] std::vector<clothcd::DetectResult> detect_each(
      const Positions& v_t0, const Positions& v_t1, std::span<const DetectOptions> configs);
  [[nodiscard]] std::vector<clothcd::DetectResult> detect_each(
      std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
      std::span<const DetectOptions> configs);

  [[nodiscard]] const DetectOptions& options() const { return options_; }
  /// As clothcd::SelfDetector::set_options, the research options included.
  void set_options(const DetectOptions& options);

 private:
  DetectOptions options_;
};

}  // namespace clothcd::research
