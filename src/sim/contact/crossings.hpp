#pragma once
// Triangle pairs already crossing at the substep start (sorted): CCD cannot undo a crossing, so
// their feature pairs are left out of the CCD response (Baraff, Witkin, Kass 2003) instead of
// filling every pass and zone round with hits that no velocity can remove.

#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "clothcd/sim/intersections.hpp"
#include "sim/contact/geometry.hpp"

namespace clothcd::sim::detail {

class Crossings {
 public:
  /// Counts this substep's crossing pairs (cloth self when `self`, cloth-body when `body`),
  /// unless the last substep provably ended crossing-free where this one starts.
  void find(const SubstepContext& ctx, const ContactGeometry& g, bool self, bool body);
  /// Records how the substep ended: with `clean` (every hit resolved, nothing excluded) and no
  /// crossing at its start, it ends crossing-free at x0 + h v.
  void end(const ContactGeometry& g, std::span<const Vec3> v, bool clean);

  /// (cloth face, body face) pairs crossing at the substep start.
  [[nodiscard]] const std::vector<std::pair<int, int>>& body_pairs() const { return body_; }
  [[nodiscard]] bool none() const { return self_.empty() && body_.empty(); }

  // A feature pair is tangled when a face around one side crosses a face around the other.
  [[nodiscard]] bool vf_tangled(const Topology& cloth, int v, int f) const;
  [[nodiscard]] bool ee_tangled(const Topology& cloth, int a, int b) const;
  [[nodiscard]] bool cloth_vertex_body_face(const ContactGeometry& g, int v, int body_face) const;
  [[nodiscard]] bool body_vertex_cloth_face(const ContactGeometry& g, int u, int cloth_face) const;
  [[nodiscard]] bool cloth_edge_body_edge(const ContactGeometry& g, int a, int b) const;

 private:
  [[nodiscard]] bool self_crossing(int f, int g) const;
  [[nodiscard]] bool body_crossing(int f, int g) const;

  std::optional<IntersectionCounter> counter_;
  std::vector<std::pair<int, int>> self_, body_;
  bool clean_end_ = false;         // the last substep provably ended crossing-free ...
  std::vector<Vec3> expected_x0_;  // ... at these positions
};

}  // namespace clothcd::sim::detail
