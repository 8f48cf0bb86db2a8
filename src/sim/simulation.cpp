// Frame loop with adaptive substeps.
#include "clothcd/sim/simulation.hpp"

#include <chrono>

namespace clothcd::sim {

Simulation::Simulation(Scene scene) : scene_(std::move(scene)) {
  model_ = std::make_unique<ClothModel>(scene_.cloth, scene_.material);
  solver_ = std::make_unique<ClothSolver>(*model_, scene_.solver);
  for (const PinGroup& g : scene_.pins)
    solver_->add_pins(g, model_->initial_positions());
  solver_->set_body(scene_.body.get());
  state_ = solver_->initial_state();
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
  fs.substeps = scene_.substeps.count(fs.body_displacement);
  const double h = scene_.frame_dt / fs.substeps;
  for (int k = 0; k < fs.substeps; ++k) {
    state_.time = t0 + k * h;  // no drift: substep starts are exact multiples
    const StepStats st = solver_->step(state_, h);
    fs.solves += st.solves;
    fs.pcg_iterations += st.pcg_iterations;
    fs.max_pcg_iterations = std::max(fs.max_pcg_iterations, st.max_pcg_iterations);
    fs.halvings += st.halvings;
    fs.pcg_converged = fs.pcg_converged && st.converged;
    fs.collision_seconds += st.collision.seconds;
  }
  state_.time = t1;
  ++frame_;
  fs.frame = frame_;
  fs.time = t1;
  fs.max_stretch = solver_->max_stretch(state_.x);
  for (const Vec3& x : state_.x)
    fs.finite = fs.finite && x.allFinite();
  for (const Vec3& v : state_.v)
    fs.finite = fs.finite && v.allFinite();
  fs.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return fs;
}

}  // namespace clothcd::sim
