// Frame loop with adaptive substeps.
#include "clothcd/sim/simulation.hpp"

#include <algorithm>
#include <chrono>

namespace clothcd::sim {

Simulation::Simulation(Scene scene) : scene_(std::move(scene)) {
  model_ = std::make_unique<ClothModel>(scene_.cloth, scene_.material);
  solver_ = std::make_unique<ClothSolver>(*model_, scene_.solver);
  for (const PinGroup& g : scene_.pins)
    solver_->add_pins(g, model_->initial_positions());
  solver_->set_body(scene_.body.get());
  if (scene_.collisions) {
    contact_ = std::make_unique<ContactHandler>(*model_, scene_.contact);
    solver_->set_collision_handler(contact_.get());
  }
  static const std::vector<Face> kNoFaces;
  counter_ = std::make_unique<IntersectionCounter>(model_->topology(), model_->seam_links(),
                                                   scene_.body ? scene_.body->faces() : kNoFaces,
                                                   scene_.body ? scene_.body->num_vertices() : 0);
  state_ = solver_->initial_state();
  if (scene_.collisions && scene_.contact.self && scene_.repair_initial_crossings) {
    std::vector<std::uint8_t> pinned(state_.x.size(), 0);
    for (const PinGroup& g : scene_.pins) {
      for (int v : g.vertices)
        pinned[v] = 1;
    }
    initial_repair_ = repair_self_crossings(state_.x, *counter_, model_->topology(), pinned,
                                            0.1 * scene_.contact.thickness);
  }
}

Simulation::~Simulation() = default;

std::vector<Vec3> Simulation::body_positions() {
  std::vector<Vec3> b;
  if (scene_.body) scene_.body->positions_at(state_.time, b);
  return b;
}

IntersectionCount Simulation::count_intersections() {
  IntersectionCount c;
  c.self = static_cast<long long>(counter_->self_pairs(state_.x).size());
  if (scene_.body)
    c.body = static_cast<long long>(counter_->body_pairs(state_.x, body_positions()).size());
  return c;
}

void Simulation::set_state(ClothState state, int frame) {
  state_ = std::move(state);
  frame_ = frame;
}

FrameStats Simulation::advance_frame() {
  const auto start = std::chrono::steady_clock::now();
  const double t0 = frame_ * scene_.frame_dt;
  const double t1 = (frame_ + 1) * scene_.frame_dt;
  FrameStats fs;
  fs.body_displacement = scene_.body ? scene_.body->max_displacement(t0, t1) : 0.0;
  const double speed = scene_.substeps.cloth_speed(state_.v);
  fs.substeps = scene_.substeps.count(fs.body_displacement, speed * scene_.frame_dt);
  const double h = scene_.frame_dt / fs.substeps;
  const bool fast = fs.substeps > scene_.substeps.min;
  for (int k = 0; k < fs.substeps; ++k) {
    state_.time = t0 + k * h;  // no drift: substep starts are exact multiples
    const StepStats st = solver_->step(state_, h, fast);
    fs.pcg_tolerance = st.pcg_tolerance;
    fs.solves += st.solves;
    fs.pcg_iterations += st.pcg_iterations;
    fs.max_pcg_iterations = std::max(fs.max_pcg_iterations, st.max_pcg_iterations);
    fs.halvings += st.halvings;
    fs.pcg_converged = fs.pcg_converged && st.converged;
    fs.collision += st.collision;
    fs.strain_limit.sweeps += st.strain.sweeps;
    fs.strain_limit.projections += st.strain.projections;
    fs.strain_limit.residual = std::max(fs.strain_limit.residual, st.strain.residual);
    fs.strain_seconds += st.strain_seconds;
  }
  if (contact_) {
    fs.self_ccd = contact_->take_self_ccd_figures();
    fs.self_proximity = contact_->take_self_proximity_figures();
    fs.collision_parts = contact_->take_part_times();
  }
  state_.time = t1;
  ++frame_;
  fs.frame = frame_;
  fs.time = t1;
  fs.max_stretch = solver_->max_stretch(state_.x);
  fs.strain = strain_figures(*model_, state_.x, solver_->body_contact());
  for (const Vec3& x : state_.x)
    fs.finite = fs.finite && x.allFinite();
  for (const Vec3& v : state_.v)
    fs.finite = fs.finite && v.allFinite();
  if (scene_.count_intersections && fs.finite) {
    const auto t = std::chrono::steady_clock::now();
    const IntersectionCount c = count_intersections();
    fs.self_intersections = c.self;
    fs.body_intersections = scene_.body ? c.body : 0;
    fs.intersection_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  }
  fs.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return fs;
}

}  // namespace clothcd::sim
