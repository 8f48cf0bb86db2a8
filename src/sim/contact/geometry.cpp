// Contacts as weighted points, their normals and gaps, and impulses on them.
#include "sim/contact/geometry.hpp"

#include "clothcd/ccd/proximity.hpp"

namespace clothcd::sim::detail {

bool normalize(Vec3& n) {
  const double l = n.norm();
  if (!(l > 1e-14)) return false;
  n /= l;
  return true;
}

ContactGeometry::ContactGeometry(const ClothModel& model) : model_(model) {}

void ContactGeometry::start(const SubstepContext& ctx) {
  x0 = ctx.x0;
  b0 = ctx.body_t0;
  b1 = ctx.body_t1;
  h = ctx.h;
  inv_mass = ctx.inverse_mass;
}

void ContactGeometry::start_response(bool with_body) {
  vb.assign(b0.size(), Vec3::Zero());
  if (!with_body) return;
  for (std::size_t i = 0; i < b0.size(); ++i)
    vb[i] = (b1[i] - b0[i]) / h;
}

const Vec3& ContactGeometry::position(const Contact& c, int k, double tau, std::span<const Vec3> v,
                                      Vec3& tmp) const {
  const int i = c.id[k];
  if (c.on_body[k]) {
    tmp = b0[i] + tau * (b1[i] - b0[i]);
  } else {
    tmp = tau == 0.0 ? x0[i] : Vec3(x0[i] + tau * h * v[i]);
  }
  return tmp;
}

Vec3 ContactGeometry::relative_velocity(const Contact& c, std::span<const Vec3> v) const {
  Vec3 r = Vec3::Zero();
  for (int k = 0; k < 4; ++k)
    r += c.c[k] * velocity(c, k, v);
  return r;
}

bool ContactGeometry::impulse(const Contact& c, const Vec3& dir, double delta,
                              std::span<Vec3> v) const {
  double denom = 0.0;
  for (int k = 0; k < 4; ++k)
    denom += c.c[k] * c.c[k] * weight(c, k);
  if (!(denom > 0.0)) return false;
  const double j = delta / denom;
  for (int k = 0; k < 4; ++k) {
    if (!c.on_body[k]) v[c.id[k]] += (c.c[k] * j * weight(c, k)) * dir;
  }
  return true;
}

bool ContactGeometry::finish(Contact& c, Vec3 n, std::span<const Vec3> v,
                             const Vec3& fallback) const {
  if (!normalize(n)) {
    n = fallback;
    if (!normalize(n)) return false;
  }
  Vec3 tmp, s = Vec3::Zero();
  for (int k = 0; k < 4; ++k)
    s += c.c[k] * position(c, k, 0.0, v, tmp);
  c.gap = n.dot(s);
  if (c.gap < 0) {
    n = -n;
    c.gap = -c.gap;
  }
  c.n = n;
  return true;
}

bool ContactGeometry::make_vf(Contact& c, int p, bool p_body, int f, bool f_body, double tau,
                              std::span<const Vec3> v) const {
  const Face& t = f_body ? body().faces()[f] : cloth().faces()[f];
  c.id = {p, t[0], t[1], t[2]};
  c.on_body = {p_body, f_body, f_body, f_body};
  std::array<Vec3, 4> q;
  for (int k = 0; k < 4; ++k)
    q[k] = position(c, k, tau, v, q[k]);
  const PointTriangleProximity pr = point_triangle_proximity(q[0], q[1], q[2], q[3]);
  c.c = {1.0, -pr.weights[0], -pr.weights[1], -pr.weights[2]};
  const Vec3 face_n = (q[2] - q[1]).cross(q[3] - q[1]);
  const Vec3 toward = q[0] - pr.closest;
  // Proximity uses the closest-point direction; CCD (touching) the face normal.
  if (tau == 0.0 && pr.distance > 1e-9) return finish(c, toward, v, face_n);
  return finish(c, face_n, v, toward);
}

bool ContactGeometry::make_ee(Contact& c, int ea, bool a_body, int eb, bool b_body, double tau,
                              std::span<const Vec3> v) const {
  const Edge& x = a_body ? body().edges()[ea] : cloth().edges()[ea];
  const Edge& y = b_body ? body().edges()[eb] : cloth().edges()[eb];
  c.id = {x[0], x[1], y[0], y[1]};
  c.on_body = {a_body, a_body, b_body, b_body};
  std::array<Vec3, 4> q;
  for (int k = 0; k < 4; ++k)
    q[k] = position(c, k, tau, v, q[k]);
  const EdgeEdgeProximity pr = edge_edge_proximity(q[0], q[1], q[2], q[3]);
  c.c = {1.0 - pr.s, pr.s, -(1.0 - pr.t), -pr.t};
  const Vec3 cross = (q[1] - q[0]).cross(q[3] - q[2]);
  const Vec3 toward = pr.closest_a - pr.closest_b;
  if (tau == 0.0 && pr.distance > 1e-9) return finish(c, toward, v, cross);
  return finish(c, cross, v, toward);
}

}  // namespace clothcd::sim::detail
