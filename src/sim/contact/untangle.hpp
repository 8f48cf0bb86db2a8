#pragma once
// Cloth vertices inside the body (behind a body face that one of their faces crosses): each
// moves out along that face's outward normal, up to ContactOptions::untangle_step per substep,
// and its body pairs (which would hold it inside) are left out of repulsion and CCD meanwhile.

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "sim/contact/geometry.hpp"

namespace clothcd::sim::detail {

class Escapes {
 public:
  /// The escaping vertices of this substep, from the crossing (cloth face, body face) pairs:
  /// none when `untangle_step` is not positive. `thickness`: the distance in front of the face
  /// they escape to.
  void find(const ContactGeometry& g, const std::vector<std::pair<int, int>>& crossing_body,
            double thickness, double untangle_step);
  /// Moves the escaping vertices out of the body relative to the face they are behind.
  void apply(const ContactGeometry& g, std::span<Vec3> v, double untangle_step) const;

  // Whether a body pair with this cloth feature is left out: the feature touches an escaping
  // vertex (a vertex; a face or edge with one).
  [[nodiscard]] bool vertex(int v) const { return escaping_[v] != 0; }
  [[nodiscard]] bool face(const Face& f) const {
    return escaping_[f[0]] || escaping_[f[1]] || escaping_[f[2]];
  }
  [[nodiscard]] bool edge(const Edge& e) const { return escaping_[e[0]] || escaping_[e[1]]; }

 private:
  struct Escape {
    int vertex = -1;
    int body_face = -1;
    Vec3 n = Vec3::Zero();
    double push = 0.0;  // metres still to go
  };
  std::vector<Escape> escapes_;
  std::vector<std::uint8_t> escaping_;  // per cloth vertex
};

}  // namespace clothcd::sim::detail
