// Refit: swept boxes and normal cones, level by level from the deepest, each level in parallel.

#include <tbb/parallel_for.h>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <numbers>

#include "clothcd/bvh/bvh.hpp"
#include "core/moved_vertices.hpp"
#include "geometry/patch_cone.hpp"

namespace clothcd {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

NormalCone full_cone() {
  return NormalCone{Eigen::Vector3d::UnitZ(), std::numbers::pi};
}

LeafConePolicy leaf_policy(ConePolicy p) {
  switch (p) {
    case ConePolicy::Provot:
      return LeafConePolicy::Tang;
    case ConePolicy::Proposed:
      return LeafConePolicy::Proposed;
    case ConePolicy::Exact:
      return LeafConePolicy::Exact;
  }
  return LeafConePolicy::Exact;
}

void set_box(BvhNode& n, std::initializer_list<const Eigen::Vector3d*> pts) {
  for (int k = 0; k < 3; ++k) {
    n.lo[k] = kInf;
    n.hi[k] = -kInf;
  }
  for (const Eigen::Vector3d* p : pts) {
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = std::min(n.lo[k], (*p)[k]);
      n.hi[k] = std::max(n.hi[k], (*p)[k]);
    }
  }
}

}  // namespace

template <class LeafFn, class PatchFn>
void Bvh::refit_levels(const RefitOptions& options, bool optimal_cones,
                       std::span<const std::uint8_t> only, int min_count, LeafFn&& leaf,
                       PatchFn&& patch) {
  const bool optimal = options.cones && optimal_cones;
  // A node below min_count triangles gets a cone only where its parent merges it (from its
  // triangles at once, by `patch`); the nodes below it get none.
  auto child_cone = [&](int c) -> const NormalCone& {
    if (nodes_[c].count < min_count && (only.empty() || only[c] != 0)) cones_[c] = patch(c);
    return cones_[c];
  };
  // The cones are allocated by the first refit that fits them (a box-only detector never pays
  // for them: a 4M-triangle tree's cones take 256 MB).
  if (options.cones && cones_.size() != nodes_.size()) cones_.resize(nodes_.size());
  if (optimal) {
    control_dirs_.resize(3 * prim_ids_.size());
    degenerate_.resize(prim_ids_.size());
  }
  // An optimal cone costs time linear in the node's size, so the few nodes of the upper levels
  // hold most of the work: split those levels down to single nodes.
  const int grain = optimal ? 1 : 256;
  for (int d = depth() - 1; d >= 0; --d) {
    tbb::parallel_for(tbb::blocked_range<int>(level_offsets_[d], level_offsets_[d + 1], grain),
                      [&](const tbb::blocked_range<int>& range) {
                        for (int i = range.begin(); i != range.end(); ++i) {
                          if (!only.empty() && only[i] == 0) continue;
                          BvhNode& n = nodes_[i];
                          if (n.is_leaf()) {
                            leaf(n, i);
                            continue;
                          }
                          const BvhNode& l = nodes_[n.left];
                          const BvhNode& r = nodes_[n.left + 1];
                          for (int k = 0; k < 3; ++k) {
                            n.lo[k] = std::min(l.lo[k], r.lo[k]);
                            n.hi[k] = std::max(l.hi[k], r.hi[k]);
                          }
                          if (!options.cones || n.count < min_count) continue;
                          const NormalCone& cl = child_cone(n.left);
                          const NormalCone& cr = child_cone(n.left + 1);
                          // Saturation is monotone up the tree: an enclosing cone is at least as
                          // wide.
                          if (cl.saturated() || cr.saturated()) {
                            cones_[i] = full_cone();
                          } else if (!optimal && options.policy == ConePolicy::Provot) {
                            cones_[i] = merge_provot(cl, cr);
                          } else if (!optimal) {
                            cones_[i] = merge_tight(cl, cr);
                          } else {
                            // The children's cones enclose their halves of the node's
                            // directions: their rim directions start the search.
                            const ConePart parts[2] = {{3 * static_cast<std::size_t>(l.count), cl},
                                                       {3 * static_cast<std::size_t>(r.count), cr}};
                            cones_[i] = optimal_cone(
                                std::span<const Eigen::Vector3d>(
                                    control_dirs_.data() + 3 * static_cast<std::size_t>(n.first),
                                    3 * static_cast<std::size_t>(n.count)),
                                parts);
                          }
                        }
                      });
  }
}

void Bvh::forget_changes() {
  changed_options_.reset();
  changed_t0_.clear();
  changed_t1_.clear();
}

void Bvh::refit(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
                const RefitOptions& options) {
  refit_with(v_t0, v_t1, options, false);
}
void Bvh::refit_changed(std::span<const Eigen::Vector3d> v_t0,
                        std::span<const Eigen::Vector3d> v_t1, const RefitOptions& options) {
  refit_changed_with(v_t0, v_t1, options, false);
}
void Bvh::refit_moved(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
                      const RefitOptions& options, std::span<const std::uint8_t> moved) {
  refit_moved_with(v_t0, v_t1, options, moved, false);
}
void Bvh::refit(std::span<const Eigen::Vector3d> v, const RefitOptions& options) {
  refit_static_with(v, options, false);
}

void Bvh::refit_with(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
                     const RefitOptions& options, bool optimal) {
  forget_changes();
  refit_nodes(v_t0, v_t1, options, optimal, {});
}

void Bvh::refit_changed_with(std::span<const Eigen::Vector3d> v_t0,
                             std::span<const Eigen::Vector3d> v_t1, const RefitOptions& options,
                             bool optimal) {
  if (changed_options_ != options || changed_optimal_ != optimal) forget_changes();
  const auto moved = detail::moved_vertices(changed_t0_, changed_t1_, v_t0, v_t1);
  refit_flagged(v_t0, v_t1, options, optimal,
                moved ? std::span<const std::uint8_t>(*moved) : std::span<const std::uint8_t>{});
}

void Bvh::refit_moved_with(std::span<const Eigen::Vector3d> v_t0,
                           std::span<const Eigen::Vector3d> v_t1, const RefitOptions& options,
                           std::span<const std::uint8_t> moved, bool optimal) {
  if (changed_options_ != options || changed_optimal_ != optimal ||
      moved.size() != static_cast<std::size_t>(num_vertices_)) {
    moved = {};
  }
  // refit_changed()'s copies are now stale: its next call refits everything and keeps new ones.
  changed_t0_.clear();
  changed_t1_.clear();
  refit_flagged(v_t0, v_t1, options, optimal, moved);
}

void Bvh::refit_flagged(std::span<const Eigen::Vector3d> v_t0,
                        std::span<const Eigen::Vector3d> v_t1, const RefitOptions& options,
                        bool optimal, std::span<const std::uint8_t> moved) {
  std::vector<std::uint8_t> touched;
  if (!moved.empty()) {
    const std::vector<Face>& faces = this->faces();
    touched.assign(faces.size(), 0);
    for (std::size_t f = 0; f < faces.size(); ++f) {
      for (int v : faces[f])
        touched[f] |= moved[v];
    }
  }
  refit_nodes(v_t0, v_t1, options, optimal,
              moved.empty() ? std::vector<std::uint8_t>{} : nodes_holding(touched));
  changed_options_ = options;
  changed_optimal_ = optimal;
}

void Bvh::refit_nodes(std::span<const Eigen::Vector3d> v_t0, std::span<const Eigen::Vector3d> v_t1,
                      const RefitOptions& options, bool optimal_cones,
                      std::span<const std::uint8_t> nodes) {
  const double margin = 0.5 * options.thickness;
  // Optimal cones start from exact leaf caps.
  const LeafConePolicy lp = optimal_cones ? LeafConePolicy::Exact : leaf_policy(options.policy);
  const bool optimal = options.cones && optimal_cones;
  const std::vector<Face>& faces = this->faces();
  // Optimal cones need every leaf's control directions.
  const int min_count = optimal ? 0 : options.cone_min_triangles;
  auto patch = [&](int i) {
    const BvhNode& n = nodes_[i];
    return detail::patch_ccd_cone(faces, std::span<const int>(prim_ids_).subspan(n.first, n.count),
                                  v_t0, v_t1);
  };
  auto leaf = [&](BvhNode& n, int i) {
    const Face& t = prim_faces_[n.first];
    const Eigen::Vector3d &a0 = v_t0[t[0]], &b0 = v_t0[t[1]], &c0 = v_t0[t[2]];
    const Eigen::Vector3d &a1 = v_t1[t[0]], &b1 = v_t1[t[1]], &c1 = v_t1[t[2]];
    set_box(n, {&a0, &b0, &c0, &a1, &b1, &c1});
    inflate(n.lo, n.hi, margin);
    if (!options.cones || n.count < min_count) return;
    cones_[i] = ccd_leaf_cone(a0, b0, c0, a1, b1, c1, lp);
    if (optimal) {
      // Bernstein control vectors of the quadratic normal n(t) (docs/algorithms.md 1.3).
      const Eigen::Vector3d n0 = (b0 - a0).cross(c0 - a0);
      const Eigen::Vector3d n1 = (b1 - a1).cross(c1 - a1);
      const Eigen::Vector3d nx = 0.5 * ((b0 - a0).cross(c1 - a1) + (b1 - a1).cross(c0 - a0));
      Eigen::Vector3d* d = control_dirs_.data() + 3 * static_cast<std::size_t>(n.first);
      const bool bad = !(n0.norm() > 0) || !(nx.norm() > 0) || !(n1.norm() > 0);
      degenerate_[n.first] = bad ? 1 : 0;
      d[0] = bad ? Eigen::Vector3d::UnitZ() : n0.normalized();
      d[1] = bad ? Eigen::Vector3d::UnitZ() : nx.normalized();
      d[2] = bad ? Eigen::Vector3d::UnitZ() : n1.normalized();
      if (bad) cones_[i] = full_cone();
    }
  };
  refit_levels(options, optimal_cones, nodes, min_count, leaf, patch);
}

void Bvh::refit_static_with(std::span<const Eigen::Vector3d> v, const RefitOptions& options,
                            bool optimal_cones) {
  forget_changes();
  const double margin = 0.5 * options.thickness;
  const bool optimal = options.cones && optimal_cones;
  auto leaf = [&](BvhNode& n, int i) {
    const Face& t = prim_faces_[n.first];
    const Eigen::Vector3d &a = v[t[0]], &b = v[t[1]], &c = v[t[2]];
    set_box(n, {&a, &b, &c});
    inflate(n.lo, n.hi, margin);
    if (!options.cones) return;
    cones_[i] = dcd_leaf_cone(a, b, c);
    if (optimal) {
      const Eigen::Vector3d nrm = (b - a).cross(c - a);
      const bool bad = !(nrm.norm() > 0);
      Eigen::Vector3d* d = control_dirs_.data() + 3 * static_cast<std::size_t>(n.first);
      degenerate_[n.first] = bad ? 1 : 0;
      d[0] = d[1] = d[2] = bad ? Eigen::Vector3d::UnitZ() : nrm.normalized();
      if (bad) cones_[i] = full_cone();
    }
  };
  // Static cones are cheap and rarely used: every node gets one.
  refit_levels(options, optimal_cones, {}, 0, leaf, [](int) { return full_cone(); });
}

double Bvh::box_area_ratio() const {
  double internal = 0.0, leaves = 0.0;
  for (const BvhNode& n : nodes_) {
    const double dx = n.hi[0] - n.lo[0], dy = n.hi[1] - n.lo[1], dz = n.hi[2] - n.lo[2];
    (n.is_leaf() ? leaves : internal) += dx * dy + dy * dz + dz * dx;
  }
  if (leaves > 0.0) return internal / leaves;
  return internal > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
}

}  // namespace clothcd
