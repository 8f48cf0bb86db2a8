// Rest state of the cloth: masses, membrane rest frames, the sliver rule, hinges and stitches.
#include "clothcd/sim/cloth_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "clothcd/core/error.hpp"

namespace clothcd::sim {
namespace {

Vec3 rest_point(const ClothMeshInput& in, int v) {
  if (in.pattern.empty()) return in.positions[v];
  return {in.pattern[v].x(), in.pattern[v].y(), 0.0};
}

double min_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  auto angle = [](const Vec3& p, const Vec3& q, const Vec3& r) {
    const Vec3 u = q - p;
    const Vec3 v = r - p;
    return std::atan2(u.cross(v).norm(), u.dot(v));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

StitchTerm make_stitch(const Stitch& s) {
  // Merge repeated vertices and drop zero weights, so the quadratic has no duplicate slots.
  StitchTerm t;
  const std::array<int, 3> v{s.a, s.b, s.c};
  const std::array<double, 3> w{1.0, -(1.0 - s.r), -s.r};
  for (int m = 0; m < 3; ++m) {
    if (w[m] == 0.0) continue;
    int k = 0;
    while (k < t.count && t.v[k] != v[m])
      ++k;
    if (k == t.count) {
      t.v[k] = v[m];
      t.w[k] = 0.0;
      ++t.count;
    }
    t.w[k] += w[m];
  }
  return t;
}

}  // namespace

ClothModel::ClothModel(const ClothMeshInput& in, const ClothMaterial& material)
    : topology_(in.faces, static_cast<int>(in.positions.size())),
      material_(material),
      moduli_(membrane_moduli(material.stretch_stiffness, material.poisson)),
      initial_(in.positions) {
  const int n = static_cast<int>(in.positions.size());
  if (!in.pattern.empty() && static_cast<int>(in.pattern.size()) != n) {
    throw InputError(fmt::format("cloth pattern has {} points, expected one per vertex ({})",
                                 in.pattern.size(), n));
  }
  for (int v = 0; v < n; ++v) {
    if (!in.positions[v].allFinite()) {
      throw InputError(fmt::format("cloth vertex {} has a non-finite position", v));
    }
  }
  const int nf = topology_.num_faces();
  rest_.resize(nf);
  active_.assign(nf, true);
  mass_.assign(n, 0.0);
  std::vector<double> areas(nf);
  for (int f = 0; f < nf; ++f) {
    const Face& t = topology_.faces()[f];
    if (in.pattern.empty()) {
      rest_[f] = membrane_rest_3d(in.positions[t[0]], in.positions[t[1]], in.positions[t[2]]);
    } else {
      rest_[f] = membrane_rest_2d(in.pattern[t[0]], in.pattern[t[1]], in.pattern[t[2]]);
    }
    areas[f] = rest_[f].area;
    for (int v : t)
      mass_[v] += material.area_density * rest_[f].area / 3.0;
  }
  // Sliver rule (docs/simulator.md 4): no membrane on tiny or needle-like rest triangles.
  std::vector<double> sorted = areas;
  double median = 0.0;
  if (!sorted.empty()) {
    std::nth_element(sorted.begin(), sorted.begin() + nf / 2, sorted.end());
    median = sorted[nf / 2];
  }
  const double min_angle_rad = material.sliver_min_angle_deg * std::numbers::pi / 180.0;
  for (int f = 0; f < nf; ++f) {
    const Face& t = topology_.faces()[f];
    const bool sliver =
        areas[f] <= material.sliver_area_ratio * median ||
        min_angle(rest_point(in, t[0]), rest_point(in, t[1]), rest_point(in, t[2])) < min_angle_rad;
    if (sliver) {
      active_[f] = false;
      ++num_slivers_;
    }
  }
  // Hinges on manifold interior edges; flat rest state (theta-bar = 0) even for a 3D rest.
  for (int e = 0; e < topology_.num_edges(); ++e) {
    const auto ef = topology_.edge_faces(e);
    if (ef.size() != 2) continue;
    const Edge& ed = topology_.edges()[e];
    auto opposite = [&](int f) {
      for (int v : topology_.faces()[f]) {
        if (v != ed[0] && v != ed[1]) return v;
      }
      return -1;
    };
    Hinge h;
    h.v = {ed[0], ed[1], opposite(ef[0]), opposite(ef[1])};
    if (h.v[2] < 0 || h.v[3] < 0 || h.v[2] == h.v[3]) continue;
    std::array<Vec3, 4> rest;
    for (int m = 0; m < 4; ++m)
      rest[m] = rest_point(in, h.v[m]);
    h.w = bending_weights(rest, material.bending_stiffness, material.cot_clamp);
    if (h.w.scale > 0.0) hinges_.push_back(h);
  }
  for (std::size_t s = 0; s < in.stitches.size(); ++s) {
    const Stitch& st = in.stitches[s];
    for (int v : {st.a, st.b, st.c}) {
      if (v < 0 || v >= n) {
        throw InputError(fmt::format("stitch {} refers to vertex {}, expected 0..{}", s, v, n - 1));
      }
    }
    if (!(st.r >= 0.0 && st.r <= 1.0)) {
      throw InputError(fmt::format("stitch {} has ratio {}, expected 0..1", s, st.r));
    }
    StitchTerm t = make_stitch(st);
    if (t.count >= 2) stitches_.push_back(t);
  }
  link_seams();
}

void ClothModel::link_seams() {
  const int n = topology_.num_vertices();
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[a] != a)
      a = parent[a] = parent[parent[a]];
    return a;
  };
  for (const StitchTerm& t : stitches_) {
    for (int i = 0; i < t.count; ++i) {
      for (int j = i + 1; j < t.count; ++j) {
        seam_links_.emplace_back(std::min(t.v[i], t.v[j]), std::max(t.v[i], t.v[j]));
      }
      parent[find(t.v[i])] = find(t.v[0]);
    }
  }
  double length = 0.0;
  for (const Edge& e : topology_.edges())
    length += (initial_[e[0]] - initial_[e[1]]).norm();
  const double radius = topology_.num_edges() > 0 ? length / topology_.num_edges() : 0.0;
  std::vector<std::vector<int>> groups(n);
  for (const StitchTerm& t : stitches_) {
    for (int i = 0; i < t.count; ++i)
      groups[find(t.v[i])].push_back(t.v[i]);
  }
  for (auto& g : groups) {
    std::sort(g.begin(), g.end());
    g.erase(std::unique(g.begin(), g.end()), g.end());
    for (std::size_t i = 0; i < g.size(); ++i) {
      for (std::size_t j = i + 1; j < g.size(); ++j) {
        if ((initial_[g[i]] - initial_[g[j]]).norm() <= radius)
          seam_links_.emplace_back(g[i], g[j]);
      }
    }
  }
  std::sort(seam_links_.begin(), seam_links_.end());
  seam_links_.erase(std::unique(seam_links_.begin(), seam_links_.end()), seam_links_.end());
}

}  // namespace clothcd::sim
