// Implicit Euler, one Newton step, filtered PCG; substep halving on failure.
#include "clothcd/sim/integrator.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <optional>
#include <vector>

#include "clothcd/core/error.hpp"
#include "pcg.hpp"
#include "system.hpp"

namespace clothcd::sim {
namespace {
constexpr int kGrain = 1024;
// Stiffness of a contact coupling's penalty, in multiples of the pair's effective mass: the
// solve leaves about 1/(1 + scale) of the approach it would have without it.
constexpr double kCouplingScale = 100.0;

template <typename F>
void for_each_vertex(int n, const F& f) {
  tbb::parallel_for(tbb::blocked_range<int>(0, n, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i)
      f(i);
  });
}

struct PinnedVertex {
  int vertex;
  int group;
  Vec3 offset;  // rest position relative to the group's center at t = 0
};
}  // namespace

struct ClothSolver::Impl {
  explicit Impl(const ClothModel& m) : assembler(m), h(assembler.make_matrix()), limiter(m) {}
  SystemAssembler assembler;
  BlockCsr h;
  Vecs gradient, hv, b;
  std::vector<PinGroup> groups;
  std::vector<PinnedVertex> pinned;
  VertexFilter filter;
  std::vector<double> inverse_mass;
  std::vector<Vec3> body_t0, body_t1;
  std::vector<ContactConstraint> constraints;
  CouplingTerms couplings;
  std::optional<CoarseSpace> coarse;
  StrainLimiter limiter;
  std::vector<double> held_inverse_mass;  // inverse_mass, 0 where a CCD projection acted
  std::vector<Vec3> support;  // per vertex: the body contact's normal while held, else zero
  std::vector<std::uint8_t> body_contact;  // vertices of the last accepted substep's constraints

  Vec3 pin_target(const PinnedVertex& p, double t) const {
    const PinGroup& g = groups[p.group];
    const Eigen::AngleAxisd rot(g.angular_velocity * t, g.axis.normalized());
    return g.center + g.velocity * t + rot * p.offset;
  }
};

ClothSolver::ClothSolver(const ClothModel& model, const SolverOptions& options)
    : model_(model), options_(options), impl_(std::make_unique<Impl>(model)) {
  const int n = model.num_vertices();
  impl_->filter.reset(n);
  impl_->inverse_mass.resize(n);
  for (int i = 0; i < n; ++i) {
    const double m = model.mass()[i];
    // A vertex in no triangle has no mass: hold it where it is.
    if (m <= 0.0) impl_->filter.kind[i] = VertexFilter::Pinned;
    impl_->inverse_mass[i] = m > 0.0 ? 1.0 / m : 0.0;
  }
  // 0 is off; CoarseSpace rejects any other size below 2.
  if (options.coarse_aggregate != 0) impl_->coarse.emplace(impl_->h, options.coarse_aggregate);
}

ClothSolver::~ClothSolver() = default;

void ClothSolver::add_pins(const PinGroup& group, const std::vector<Vec3>& x) {
  const int n = model_.num_vertices();
  const int gid = static_cast<int>(impl_->groups.size());
  impl_->groups.push_back(group);
  for (int v : group.vertices) {
    if (v < 0 || v >= n) {
      throw InputError(fmt::format("pinned vertex {} out of range 0..{}", v, n - 1));
    }
    impl_->pinned.push_back({v, gid, x[v] - group.center});
    impl_->filter.kind[v] = VertexFilter::Pinned;
    impl_->inverse_mass[v] = 0.0;
  }
}

ClothState ClothSolver::initial_state() const {
  ClothState s;
  s.x = model_.initial_positions();
  s.v.assign(s.x.size(), Vec3::Zero());
  s.dv.assign(s.x.size(), Vec3::Zero());
  return s;
}

bool ClothSolver::try_step(ClothState& state, double h, double tolerance, StepStats& stats,
                           bool allow_fail) {
  Impl& im = *impl_;
  const int n = model_.num_vertices();
  const double beta = model_.material().damping;
  const auto& mass = model_.mass();

  SubstepContext ctx;
  if (handler_ != nullptr) {
    ctx.t0 = state.time;
    ctx.h = h;
    ctx.x0 = state.x;
    ctx.inverse_mass = im.inverse_mass;
    ctx.cloth = &model_.topology();
    if (body_ != nullptr) {
      body_->positions_at(state.time, im.body_t0);
      body_->positions_at(state.time + h, im.body_t1);
      ctx.body_t0 = im.body_t0;
      ctx.body_t1 = im.body_t1;
      ctx.body_faces = &body_->faces();
    }
    const auto start = std::chrono::steady_clock::now();
    handler_->prepare(ctx);
    stats.collision.seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  const double stretch = im.assembler.assemble(state.x, im.h, im.gradient);
  stats.max_stretch = std::max(stats.max_stretch, stretch);
  im.hv.resize(n);
  im.b.resize(n);
  multiply(im.h, state.v, im.hv);
  const Vec3 g = options_.gravity;
  for_each_vertex(
      n, [&](int i) { im.b[i] = h * (mass[i] * g - im.gradient[i] - (h + beta) * im.hv[i]); });
  // Contact constraints constrain one direction of free vertices, the first constraint of a
  // vertex only; one on no vertex or along no direction is ignored, not trusted. The filter is
  // restored however this attempt ends.
  std::vector<ContactConstraint> asked;
  if (handler_ != nullptr) handler_->contact_constraints(asked);
  im.constraints.clear();
  for (ContactConstraint c : asked) {
    const double len = c.n.norm();
    if (c.vertex < 0 || c.vertex >= n || !(len > 0.0) || !std::isfinite(len) ||
        !std::isfinite(c.normal_velocity) || im.filter.kind[c.vertex] != VertexFilter::Free)
      continue;
    if (std::abs(len - 1.0) > 1e-12) c.n /= len;  // unit normals as given, bit for bit
    im.filter.kind[c.vertex] = VertexFilter::Plane;
    im.filter.direction[c.vertex] = c.n;
    im.constraints.push_back(c);
  }
  struct RestoreFilter {
    Impl& im;
    ~RestoreFilter() {
      for (const ContactConstraint& c : im.constraints)
        im.filter.kind[c.vertex] = VertexFilter::Free;
    }
  } restore{im};
  // Start: prescribed changes on pinned vertices and along constrained directions, the previous
  // change elsewhere (warm start).
  Vecs dv(n);
  for_each_vertex(n, [&](int i) { dv[i] = im.filter.apply(i, state.dv[i]); });
  for (const PinnedVertex& p : im.pinned) {
    dv[p.vertex] = (im.pin_target(p, state.time + h) - state.x[p.vertex]) / h - state.v[p.vertex];
  }
  for (const ContactConstraint& c : im.constraints)
    dv[c.vertex] += c.n * (c.normal_velocity - c.n.dot(state.v[c.vertex]));
  // Contact couplings: penalties on the pairs' relative normal velocities, in the matrix and
  // in the right-hand side.
  std::vector<ContactCoupling> asked_couplings;
  if (handler_ != nullptr) handler_->contact_couplings(asked_couplings);
  im.couplings.reset(asked_couplings, im.inverse_mass, kCouplingScale);
  const CouplingTerms* ct = im.couplings.empty() ? nullptr : &im.couplings;
  Vecs rhs = im.b;
  if (ct != nullptr) ct->add_rhs(state.v, rhs);
  const PcgOptions pcg{options_.pcg_max_iterations, tolerance};
  const double c = h * (h + beta);
  PcgOptions first = pcg;
  if (!im.constraints.empty() || ct != nullptr)
    first.tolerance = std::max(pcg.tolerance, options_.release_tolerance);
  const CoarseSpace* coarse = nullptr;
  if (im.coarse) {
    im.coarse->update(im.h, c, mass, ct);
    coarse = &*im.coarse;
  }
  PcgResult res = solve_pcg(im.h, c, mass, rhs, im.filter, first, dv, ct, coarse);
  ++stats.solves;
  stats.pcg_iterations += res.iterations;
  stats.max_pcg_iterations = std::max(stats.max_pcg_iterations, res.iterations);
  // A constraint whose force would pull its vertex onto the body, and a coupling that would hold
  // its pair together, are let go, and the solve redone from where it stopped (Baraff & Witkin
  // 1998 release the next step; here the same one). The redo also completes a first solve that
  // stopped at release_tolerance.
  if ((!im.constraints.empty() || ct != nullptr) && std::isfinite(res.relative_residual)) {
    Vecs q(n);
    apply_system(im.h, c, mass, dv, q, ct);
    bool released = false;
    for (const ContactConstraint& cc : im.constraints) {
      const int i = cc.vertex;
      if (im.filter.kind[i] != VertexFilter::Plane) continue;
      if (cc.n.dot(rhs[i] - q[i]) > 0.0) {  // the residual is minus the constraint's force
        im.filter.kind[i] = VertexFilter::Free;
        released = true;
      }
    }
    if (ct != nullptr && im.couplings.release_adhesive(state.v, dv) > 0) {
      released = true;
      rhs = im.b;
      ct->add_rhs(state.v, rhs);
    }
    if (released || (first.tolerance > pcg.tolerance && res.relative_residual > pcg.tolerance)) {
      res = solve_pcg(im.h, c, mass, rhs, im.filter, pcg, dv, ct, coarse);
      stats.pcg_iterations += res.iterations;
      stats.max_pcg_iterations = std::max(stats.max_pcg_iterations, res.iterations);
    }
  }
  bool finite = std::isfinite(res.relative_residual);
  for (int i = 0; i < n && finite; ++i)
    finite = dv[i].allFinite();
  if (!allow_fail && (!finite || res.relative_residual > options_.halve_residual)) return false;
  if (!res.converged) stats.converged = false;

  Vecs v_star(n);
  for_each_vertex(n, [&](int i) { v_star[i] = state.v[i] + dv[i]; });
  // Strain limiting on the end positions, before the collision stage: its CCD passes see the
  // limited motion, so the frames stay crossing-free (docs/simulator.md 2.2).
  if (im.limiter.enabled()) {
    const auto start = std::chrono::steady_clock::now();
    im.support.assign(im.constraints.empty() ? 0 : n, Vec3::Zero());
    for (const ContactConstraint& cc : im.constraints) {
      if (im.filter.kind[cc.vertex] == VertexFilter::Plane) im.support[cc.vertex] = cc.n;
    }
    const StrainLimitStats ls =
        im.limiter.apply(state.x, h, im.inverse_mass, im.support, v_star, options_.strain_sweeps);
    stats.strain.sweeps += ls.sweeps;
    stats.strain.projections += ls.projections;
    stats.strain.residual = std::max(stats.strain.residual, ls.residual);
    stats.strain_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  // Again in the collision stage: once before its first CCD pass (repulsion and friction
  // changed velocities everywhere; that pass tests every pair anyway), then after the first
  // passes' projections, which stop single vertices while their neighbours move on. There the
  // vertices the projection changed are held: the limiter drags their neighbours after them
  // instead of undoing the projection, which would only bring the same hits back. The next pass
  // tests what the limiter moved.
  if (handler_ != nullptr && im.limiter.enabled()) {
    ctx.after_projection = [&, calls = 0](std::span<Vec3> v,
                                          std::span<std::uint8_t> touched) mutable {
      if (calls++ > options_.strain_ccd_passes) return;  // the first call is before the passes
      const auto t0 = std::chrono::steady_clock::now();
      std::span<const std::uint8_t> start;
      std::span<const double> inverse_mass = im.inverse_mass;
      if (calls > 1) {
        start = touched;
        im.held_inverse_mass.assign(im.inverse_mass.begin(), im.inverse_mass.end());
        for (int i = 0; i < n; ++i) {
          if (touched[i]) im.held_inverse_mass[i] = 0.0;
        }
        inverse_mass = im.held_inverse_mass;
      }
      const int sweeps = calls == 1 ? options_.strain_sweeps : options_.strain_ccd_sweeps;
      const StrainLimitStats ls =
          im.limiter.apply(state.x, h, inverse_mass, im.support, v, sweeps, start);
      stats.strain.sweeps += ls.sweeps;
      stats.strain.projections += ls.projections;
      const auto moved = im.limiter.moved();
      for (int i = 0; i < n; ++i)
        touched[i] |= moved[i];
      stats.strain_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
  }
  if (handler_ != nullptr) {
    const auto start = std::chrono::steady_clock::now();
    CollisionStats cs = handler_->respond(ctx, v_star);
    cs.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Hits left by a halved attempt are not counted: its shorter substeps retry them.
    const bool halve = !allow_fail && options_.halve_unresolved && cs.unresolved > 0;
    if (halve) cs.unresolved = 0;
    stats.collision += cs;
    if (halve) return false;
  }
  for_each_vertex(n, [&](int i) {
    state.x[i] += h * v_star[i];
    state.v[i] = v_star[i];
  });
  state.dv = std::move(dv);
  state.time += h;
  im.body_contact.assign(n, 0);
  for (const ContactConstraint& cc : im.constraints)
    im.body_contact[cc.vertex] = 1;
  return true;
}

void ClothSolver::substep(ClothState& state, double h, double tolerance, int depth,
                          StepStats& stats) {
  const bool last_chance = depth >= options_.max_halvings;
  if (try_step(state, h, tolerance, stats, last_chance)) return;
  ++stats.halvings;
  substep(state, 0.5 * h, tolerance, depth + 1, stats);
  substep(state, 0.5 * h, tolerance, depth + 1, stats);
}

StepStats ClothSolver::step(ClothState& state, double h, bool fast) {
  StepStats stats;
  stats.pcg_tolerance = fast && options_.fast_pcg_tolerance > 0.0 ? options_.fast_pcg_tolerance
                                                                  : options_.pcg_tolerance;
  substep(state, h, stats.pcg_tolerance, 0, stats);
  return stats;
}

double ClothSolver::potential_energy(const std::vector<Vec3>& x) const {
  double e = impl_->assembler.elastic_energy(x);
  for (int i = 0; i < model_.num_vertices(); ++i)
    e -= model_.mass()[i] * options_.gravity.dot(x[i]);
  return e;
}

double ClothSolver::kinetic_energy(const std::vector<Vec3>& v) const {
  double e = 0.0;
  for (int i = 0; i < model_.num_vertices(); ++i)
    e += 0.5 * model_.mass()[i] * v[i].squaredNorm();
  return e;
}

const std::vector<std::uint8_t>& ClothSolver::body_contact() const {
  return impl_->body_contact;
}

double ClothSolver::max_stretch(const std::vector<Vec3>& x) const {
  const auto& faces = model_.topology().faces();
  // In parallel: a maximum is the same whatever the grouping (a NaN is skipped either way).
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, model_.topology().num_faces(), 2048), 0.0,
      [&](const tbb::blocked_range<int>& r, double s) {
        for (int f = r.begin(); f < r.end(); ++f) {
          if (!model_.membrane_active()[f]) continue;
          const Face& t = faces[f];
          s = std::max(s, membrane_eval({x[t[0]], x[t[1]], x[t[2]]}, model_.membrane_rest()[f],
                                        model_.moduli(), true)
                              .max_stretch);
        }
        return s;
      },
      [](double a, double b) { return std::max(a, b); });
}

}  // namespace clothcd::sim
