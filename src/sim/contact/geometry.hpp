#pragma once
// One substep's contact geometry: a contact as four weighted points of the cloth and the body,
// built at some time of the substep, and the impulses that change its relative velocity.

#include <array>
#include <span>
#include <vector>

#include "clothcd/detect/detector.hpp"
#include "clothcd/sim/cloth_model.hpp"
#include "clothcd/sim/collision.hpp"

namespace clothcd::sim::detail {

// A contact as four points with signed weights c_k (docs/simulator.md 3.2): VF is
// (1, -w0, -w1, -w2), EE is (1 - s, s, -(1 - t), -t). `n` points from the negative side to the
// positive one; `gap` is the signed distance n . sum c_k x_k at the substep start.
struct Contact {
  std::array<int, 4> id{};
  std::array<bool, 4> on_body{};
  std::array<double, 4> c{};
  Vec3 n = Vec3::Zero();
  double gap = 0.0;
  double sep = 0.0;  // CCD separation this pair was tested with
};

// Scales n to unit length; false (n unchanged) when it is too short to have a direction.
bool normalize(Vec3& n);

/// The cloth and the body of one substep: start positions, the body's motion, masses.
class ContactGeometry {
 public:
  explicit ContactGeometry(const ClothModel& model);

  /// Takes the substep's positions (the cloth's and the body's; no copy).
  void start(const SubstepContext& ctx);
  /// The body's velocities over the substep (zero without a body).
  void start_response(bool with_body);
  /// The body's topology, once known (the contact stage's body detector owns it).
  void set_body(const Topology* body) { body_ = body; }

  [[nodiscard]] const Topology& cloth() const { return model_.topology(); }
  [[nodiscard]] const Topology& body() const { return *body_; }
  [[nodiscard]] const ClothModel& model() const { return model_; }

  [[nodiscard]] const Vec3& position(const Contact& c, int k, double tau, std::span<const Vec3> v,
                                     Vec3& tmp) const;
  [[nodiscard]] Vec3 velocity(const Contact& c, int k, std::span<const Vec3> v) const {
    return c.on_body[k] ? vb[c.id[k]] : v[c.id[k]];
  }
  [[nodiscard]] double weight(const Contact& c, int k) const {
    return c.on_body[k] ? 0.0 : inv_mass[c.id[k]];
  }
  [[nodiscard]] Vec3 relative_velocity(const Contact& c, std::span<const Vec3> v) const;
  // Changes the contact's relative velocity by delta * dir; false when every point is fixed.
  bool impulse(const Contact& c, const Vec3& dir, double delta, std::span<Vec3> v) const;

  // A vertex-face contact at time tau of the substep (0: proximity at the start).
  bool make_vf(Contact& c, int p, bool p_body, int f, bool f_body, double tau,
               std::span<const Vec3> v) const;
  bool make_ee(Contact& c, int ea, bool a_body, int eb, bool b_body, double tau,
               std::span<const Vec3> v) const;

  // The substep: positions, body velocities, masses.
  std::span<const Vec3> x0, b0, b1;
  std::vector<Vec3> vb;
  std::span<const double> inv_mass;
  double h = 0.0;

 private:
  // Orients n so that the contact's start gap is >= 0; false for a degenerate normal.
  bool finish(Contact& c, Vec3 n, std::span<const Vec3> v, const Vec3& fallback) const;

  const ClothModel& model_;
  const Topology* body_ = nullptr;
};

}  // namespace clothcd::sim::detail
