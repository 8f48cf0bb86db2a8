#pragma once
/// @file
/// The candidates stage on its own: triangle pairs in (e.g. from clothcd/bvh/traverse.hpp), the
/// vertex-face and edge-edge feature pairs that SelfDetector's narrow phase would test out, with
/// no geometry test, for your own CCD kernel.
///
/// A feature pair belongs to several triangle pairs; the detector tests it in one of them only,
/// its R-triangle pair (docs/algorithms.md 6.3), and this stage yields it there only. Triangle
/// pairs that share a vertex yield nothing: the feature pairs all of whose triangle pairs share a
/// vertex, the orphans, come from orphans() instead (the detector tests them every step).
///
/// Given the same triangle pairs, the detector tests these feature pairs less those whose swept
/// boxes miss (and those its filters prove apart): a kernel that reports only features that
/// touch finds on them what the detector finds. With Culling::None the detector's triangle pairs
/// are the overlapping leaf pairs of its tree refit to the step (clothcd/bvh/traverse.hpp).

#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/mesh/topology.hpp"

namespace clothcd {

/// Feature pairs of one mesh.
struct FeaturePairs {
  std::vector<std::pair<int, int>> vf;  ///< (vertex, face)
  std::vector<std::pair<int, int>> ee;  ///< (edge a, edge b), a < b, ids of Topology::edges()
  bool operator==(const FeaturePairs&) const = default;
};

class Candidates {
 public:
  /// Copies what it needs of `topology` (it need not outlive this object). `linked_vertices` as
  /// DetectOptions::linked_vertices: feature pairs with a vertex linked to one of the other
  /// feature's are left out, as the detector leaves them out. Throws clothcd::InputError for a
  /// linked id outside [0, num_vertices).
  explicit Candidates(const Topology& topology,
                      std::span<const std::pair<int, int>> linked_vertices = {});
  ~Candidates();
  Candidates(Candidates&&) noexcept;
  Candidates& operator=(Candidates&&) noexcept;

  /// Appends the feature pairs whose R-triangle pair is (f, g) (either order), unsorted; nothing
  /// when f and g share a vertex. Const: threads may call it at once, each with its own `out`.
  void append(int f, int g, FeaturePairs& out) const;

  /// The orphan pairs, sorted (linked ones left out).
  [[nodiscard]] const FeaturePairs& orphans() const;

  /// The feature pairs of all `triangle_pairs` and the orphans: sorted, each once (a triangle
  /// pair listed twice, in either order, adds nothing).
  [[nodiscard]] FeaturePairs operator()(std::span<const std::pair<int, int>> triangle_pairs) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothcd
