// Crossing triangle pairs at the substep start and the feature pairs they tangle.
#include "sim/contact/crossings.hpp"

#include <algorithm>

namespace clothcd::sim::detail {

void Crossings::find(const SubstepContext& ctx, const ContactGeometry& g, bool self, bool body) {
  static const std::vector<Face> kNoFaces;
  if (!counter_) {
    counter_.emplace(g.cloth(), g.model().seam_links(), body ? *ctx.body_faces : kNoFaces,
                     body ? static_cast<int>(ctx.body_t0.size()) : 0);
  }
  self_.clear();
  body_.clear();
  // A substep that started crossing-free, excluded nothing and resolved every CCD hit ends
  // crossing-free: skip the count when this substep starts where that one ended.
  if (clean_end_ &&
      std::equal(g.x0.begin(), g.x0.end(), expected_x0_.begin(), expected_x0_.end())) {
    return;
  }
  if (self) self_ = counter_->self_pairs(g.x0);
  if (body) body_ = counter_->body_pairs(g.x0, g.b0);
}

void Crossings::end(const ContactGeometry& g, std::span<const Vec3> v, bool clean) {
  clean_end_ = clean && none();
  if (!clean_end_) return;
  expected_x0_.resize(g.x0.size());
  for (std::size_t i = 0; i < g.x0.size(); ++i)
    expected_x0_[i] = g.x0[i] + g.h * v[i];
}

bool Crossings::self_crossing(int f, int g) const {
  return std::binary_search(self_.begin(), self_.end(),
                            std::pair<int, int>(std::min(f, g), std::max(f, g)));
}
bool Crossings::body_crossing(int f, int g) const {
  return std::binary_search(body_.begin(), body_.end(), std::pair<int, int>(f, g));
}

bool Crossings::vf_tangled(const Topology& cloth, int v, int f) const {
  if (self_.empty()) return false;
  for (int g : cloth.vertex_faces(v)) {
    if (self_crossing(g, f)) return true;
  }
  return false;
}

bool Crossings::ee_tangled(const Topology& cloth, int a, int b) const {
  if (self_.empty()) return false;
  for (int f : cloth.edge_faces(a)) {
    for (int g : cloth.edge_faces(b)) {
      if (self_crossing(f, g)) return true;
    }
  }
  return false;
}

bool Crossings::cloth_vertex_body_face(const ContactGeometry& g, int v, int body_face) const {
  if (body_.empty()) return false;
  for (int f : g.cloth().vertex_faces(v)) {
    if (body_crossing(f, body_face)) return true;
  }
  return false;
}

bool Crossings::body_vertex_cloth_face(const ContactGeometry& g, int u, int cloth_face) const {
  if (body_.empty()) return false;
  for (int b : g.body().vertex_faces(u)) {
    if (body_crossing(cloth_face, b)) return true;
  }
  return false;
}

bool Crossings::cloth_edge_body_edge(const ContactGeometry& g, int a, int b) const {
  if (body_.empty()) return false;
  for (int f : g.cloth().edge_faces(a)) {
    for (int k : g.body().edge_faces(b)) {
      if (body_crossing(f, k)) return true;
    }
  }
  return false;
}

}  // namespace clothcd::sim::detail
