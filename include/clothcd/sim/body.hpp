#pragma once
/// @file
/// Kinematic bodies the cloth meets: a triangle mesh animated by OBJ frames (linear interpolation
/// between frames, docs/simulator.md 3.4) and an analytic moving, spinning sphere (tessellated so
/// that the collision stage can treat every body as a mesh).

#include <filesystem>
#include <vector>

#include "clothcd/sim/integrator.hpp"

namespace clothcd::sim {

class Body : public BodyPositions {
 public:
  /// Largest displacement of a body point between t0 and t1 (drives the substep count).
  [[nodiscard]] virtual double max_displacement(double t0, double t1) = 0;
  [[nodiscard]] virtual int num_vertices() const = 0;
};

/// Frames B_k at times k * frame_dt, each translated by `offset`; b(t) interpolates linearly and
/// holds the last frame after the sequence ends. Frames are read lazily (two are cached).
class MeshSequenceBody final : public Body {
 public:
  /// Reads frame 0 for the topology; throws InputError naming the file on bad input.
  MeshSequenceBody(std::vector<std::filesystem::path> frames, double frame_dt, const Vec3& offset);

  void positions_at(double t, std::vector<Vec3>& out) override;
  [[nodiscard]] const std::vector<Face>& faces() const override { return faces_; }
  [[nodiscard]] double max_displacement(double t0, double t1) override;
  [[nodiscard]] int num_vertices() const override { return num_vertices_; }
  [[nodiscard]] int num_frames() const { return static_cast<int>(paths_.size()); }

 private:
  const std::vector<Vec3>& frame(int k, int keep);

  std::vector<std::filesystem::path> paths_;
  double frame_dt_;
  Vec3 offset_;
  std::vector<Face> faces_;
  int num_vertices_ = 0;
  int cached_[2] = {-1, -1};
  std::vector<Vec3> cache_[2];
};

/// A sphere moving at constant velocity and spinning about `spin_axis` (through its centre) at
/// `spin_rate` rad/s from `spin_start` on.
struct SphereMotion {
  Vec3 center = Vec3::Zero();
  double radius = 0.25;
  Vec3 velocity = Vec3::Zero();
  Vec3 spin_axis = Vec3::UnitY();
  double spin_rate = 0.0;
  double spin_start = 0.0;
};

class SphereBody final : public Body {
 public:
  /// `subdivisions` of an icosahedron give the mesh (3: 642 vertices, 1280 triangles).
  SphereBody(const SphereMotion& motion, int subdivisions);

  void positions_at(double t, std::vector<Vec3>& out) override;
  [[nodiscard]] const std::vector<Face>& faces() const override { return faces_; }
  [[nodiscard]] double max_displacement(double t0, double t1) override;
  [[nodiscard]] int num_vertices() const override { return static_cast<int>(unit_.size()); }
  [[nodiscard]] const SphereMotion& motion() const { return motion_; }
  /// Centre and spin angle at t.
  [[nodiscard]] Vec3 center_at(double t) const { return motion_.center + motion_.velocity * t; }
  [[nodiscard]] double angle_at(double t) const;

 private:
  SphereMotion motion_;
  std::vector<Vec3> unit_;
  std::vector<Face> faces_;
};

}  // namespace clothcd::sim
