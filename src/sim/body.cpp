// Kinematic bodies: OBJ frame sequences and an analytic sphere.
#include "clothcd/sim/body.hpp"

#include <fmt/format.h>

#include <cmath>
#include <map>

#include "clothcd/core/error.hpp"
#include "clothcd/mesh/io.hpp"

namespace clothcd::sim {

MeshSequenceBody::MeshSequenceBody(std::vector<std::filesystem::path> frames, double frame_dt,
                                   const Vec3& offset)
    : paths_(std::move(frames)), frame_dt_(frame_dt), offset_(offset) {
  if (paths_.empty()) throw InputError("body: no frames given");
  const TriangleMesh first = read_obj(paths_[0]);
  faces_ = first.faces;
  num_vertices_ = first.num_vertices();
}

const std::vector<Vec3>& MeshSequenceBody::frame(int k, int keep) {
  for (int s = 0; s < 2; ++s) {
    if (cached_[s] == k) return cache_[s];
  }
  const int s = cached_[0] == keep ? 1 : 0;  // never evict the frame the caller still reads
  cache_[s] = read_obj_vertices(paths_[k]);
  if (static_cast<int>(cache_[s].size()) != num_vertices_) {
    cached_[s] = -1;
    throw input_error(
        paths_[k].string(), 0,
        fmt::format("body frame has {} vertices, frame 0 has {}", cache_[s].size(), num_vertices_));
  }
  for (Vec3& p : cache_[s])
    p += offset_;
  cached_[s] = k;
  return cache_[s];
}

void MeshSequenceBody::positions_at(double t, std::vector<Vec3>& out) {
  const int last = num_frames() - 1;
  const double u = t / frame_dt_;
  int k = static_cast<int>(std::floor(u));
  double s = u - k;
  if (k >= last) {
    k = last;
    s = 0.0;
  } else if (k < 0) {
    k = 0;
    s = 0.0;
  }
  // Snap times within rounding of a frame to that frame, so frame times give exact frames.
  if (s > 1.0 - 1e-9) {
    ++k;
    s = 0.0;
  }
  out.resize(num_vertices_);
  const std::vector<Vec3>& a = frame(k, -1);
  if (s < 1e-9 || k >= last) {
    out = a;
    return;
  }
  const std::vector<Vec3>& b = frame(k + 1, k);
  for (int i = 0; i < num_vertices_; ++i)
    out[i] = (1.0 - s) * a[i] + s * b[i];
}

double MeshSequenceBody::max_displacement(double t0, double t1) {
  std::vector<Vec3> a, b;
  positions_at(t0, a);
  positions_at(t1, b);
  double d = 0.0;
  for (int i = 0; i < num_vertices_; ++i)
    d = std::max(d, (b[i] - a[i]).norm());
  return d;
}

SphereBody::SphereBody(const SphereMotion& motion, int subdivisions) : motion_(motion) {
  if (!(motion.radius > 0.0)) throw InputError("sphere: radius must be positive");
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  unit_ = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
           {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  for (Vec3& v : unit_)
    v.normalize();
  faces_ = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
            {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      unit_.push_back((unit_[a] + unit_[b]).normalized());
      const int id = static_cast<int>(unit_.size()) - 1;
      mid.emplace(key, id);
      return id;
    };
    std::vector<Face> next;
    for (const Face& f : faces_) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    faces_ = std::move(next);
  }
}

double SphereBody::angle_at(double t) const {
  return motion_.spin_rate * std::max(0.0, t - motion_.spin_start);
}

void SphereBody::positions_at(double t, std::vector<Vec3>& out) {
  const Eigen::AngleAxisd rot(angle_at(t), motion_.spin_axis.normalized());
  const Vec3 c = center_at(t);
  out.resize(unit_.size());
  for (std::size_t i = 0; i < unit_.size(); ++i)
    out[i] = c + motion_.radius * (rot * unit_[i]);
}

double SphereBody::max_displacement(double t0, double t1) {
  // Translation plus the largest arc of the spin: a bound, exact for the tessellation's needs.
  return motion_.velocity.norm() * (t1 - t0) +
         motion_.radius * std::abs(angle_at(t1) - angle_at(t0));
}

}  // namespace clothcd::sim
