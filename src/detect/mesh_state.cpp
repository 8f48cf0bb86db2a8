#include "detect/mesh_state.hpp"

#include <fmt/format.h>

#include "clothcd/core/error.hpp"

namespace clothcd::detail {
namespace {
Bvh make_tree(const Topology& topo, PointsIn reference, std::string_view what, BvhBuild build,
              bool cones) {
  std::vector<Eigen::Vector3d> points;
  to_points(reference, topo.num_vertices(), what, points);
  return cones ? Bvh(topo, points, build) : Bvh::boxes_only(topo, points, build);
}
}  // namespace

MeshState::MeshState(std::vector<Face> faces, int nv, PointsIn reference, std::string_view what,
                     BvhBuild build, bool cones, bool face_blocks)
    : topo(std::move(faces), nv), boxes(face_blocks ? BoxStore::Blocks : BoxStore::Separate) {
  bvh = make_tree(topo, reference, what, build, cones);
}

void MeshState::refit_static(double h) {
  RefitOptions ro;
  ro.thickness = h;
  ro.cones = false;  // cones carry no distance information (docs/algorithms.md 1.1)
  bvh.refit(v0, ro);
  bvh_call = 0;
}

void MeshState::set_active_vertices(std::span<const int> vertices, std::string_view mesh) {
  const int nv = topo.num_vertices();
  vertex_active.assign(nv, 0);
  for (int v : vertices) {
    if (v < 0 || v >= nv) {
      throw InputError(
          mesh.empty()
              ? fmt::format("active vertex {} is out of range [0, {})", v, nv)
              : fmt::format("active vertex {} of mesh {} is out of range [0, {})", v, mesh, nv));
    }
    vertex_active[v] = 1;
  }
  // A face then counts as active when it has an active vertex, and only such faces can
  // represent an in-scope pair.
  face_active = topo.faces_touching(vertex_active);
  edge_active = topo.edges_touching(vertex_active);
  node_active = bvh.nodes_holding(face_active);
  restricted = true;
}

void MeshState::set_active_faces(std::span<const int> faces) {
  const int nf = topo.num_faces();
  face_active.assign(nf, 0);
  vertex_active.assign(topo.num_vertices(), 0);
  edge_active.assign(topo.num_edges(), 0);
  for (int f : faces) {
    if (f < 0 || f >= nf) {
      throw InputError(fmt::format("active face {} is out of range [0, {})", f, nf));
    }
    face_active[f] = 1;
    for (int v : topo.faces()[f])
      vertex_active[v] = 1;
    for (int e : topo.face_edges(f))
      edge_active[e] = 1;
  }
  // A face touching an active vertex can be the representative of an in-scope pair.
  node_active = bvh.nodes_holding(topo.faces_touching(vertex_active));
  restricted = true;
}

void MeshState::rebuild(PointsIn reference, std::string_view what, BvhBuild build, bool cones) {
  bvh = make_tree(topo, reference, what, build, cones);
  bvh_call = 0;
  restricted = false;  // its node flags belonged to the old tree
}

}  // namespace clothcd::detail
