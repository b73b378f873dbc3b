// frame.cpp - one time step of collide_debris (frame.hpp).
//
// Design notes
// ------------
// * The order of a step is the design note's in debris.cpp: gravity, the
//   contacts, collide, the position correction, the positions. collide
//   changes velocities only, so the correction and the integration after it
//   see the solved v, and the next step's contacts the moved p.
#include "frame.hpp"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>

namespace debris {
namespace {

/// Pushes overlapping bodies apart by part of their overlap beyond a slop,
/// in proportion to inverse mass (the ground does not move). Returns the
/// potential energy this added by lifting bodies [J], so that the energy
/// check can tell it from energy the contacts would have created.
double correct_positions(World& w, const Contacts& c) {
  constexpr double kSlop = 0.002;    // [m] overlap left alone, so resting contacts persist
  constexpr double kFraction = 0.4;  // of the excess removed per step
  double lifted = 0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const double excess = c.depth[k] - kSlop;
    if (excess <= 0) continue;
    Body& a = w.bodies[c.a[k]];
    Body& b = w.bodies[c.b[k]];
    const double wa = a.inv_mass, wb = b.inv_mass;
    const double s = kFraction * excess / (wa + wb);
    a.p[0] += static_cast<Real>(s * wa * c.nx[k]);
    a.p[1] += static_cast<Real>(s * wa * c.ny[k]);
    a.p[2] += static_cast<Real>(s * wa * c.nz[k]);
    b.p[0] -= static_cast<Real>(s * wb * c.nx[k]);
    b.p[1] -= static_cast<Real>(s * wb * c.ny[k]);
    b.p[2] -= static_cast<Real>(s * wb * c.nz[k]);
    // m g dz for both sides; m * (s * w) = s for a movable body.
    lifted += kGravity * s * c.nz[k] * ((wa > 0 ? 1 : 0) - (wb > 0 ? 1 : 0));
  }
  return lifted;
}

collide::SolverOptions make_solver_options(const Options& o) {
  collide::SolverOptions solver_options;
  solver_options.threads = o.threads;
  solver_options.passes = o.passes;  // the passes of a step share its schedule
  solver_options.iteration = o.iteration == "accumulate" ? collide::Iteration::accumulate : collide::Iteration::repeat;
  solver_options.warm_start = o.warm_start;
  return solver_options;
}

std::uint64_t pair_key(collide::BodyIndex a, collide::BodyIndex b) {
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint64_t>(b);
}

}  // namespace

Frame::Frame(const Options& o, collide::Order order) : options_(o), schedule_(order), solver_(make_solver_options(o)) {}

StepFigures Frame::step(World& world) {
  const Options& o = options_;
  StepFigures f;
  const Real dv = static_cast<Real>(kGravity * o.dt);
  for (std::size_t i = 1; i < world.size(); ++i) world.bodies[i].v[2] -= dv;

  grid_.find_contacts(world, o.friction, contacts_);
  const collide::ContactView<Real> view = contacts_.view(o.restitution);
  const collide::ImpulseView<Real> impulses = contacts_.impulses();
  const collide::PackedView<Body> bodies = world.view();
  if (o.warm_start) {
    // The warm start: each contact's J from the last step's contact of the
    // same two bodies, re-expressed about this step's normal (the normal
    // part along it, the friction part in its tangent plane), 0 for a pair
    // that just met.
    for (std::size_t k = 0; k < contacts_.size(); ++k) {
      const auto it = last_j_.find(pair_key(contacts_.a[k], contacts_.b[k]));
      if (it == last_j_.end()) {
        contacts_.jx[k] = contacts_.jy[k] = contacts_.jz[k] = 0;
        continue;
      }
      const Real n[3] = {contacts_.nx[k], contacts_.ny[k], contacts_.nz[k]};
      const std::array<Real, 3>& g = it->second.friction;
      const Real along = g[0] * n[0] + g[1] * n[1] + g[2] * n[2];
      const Real lambda = it->second.lambda;
      contacts_.jx[k] = lambda * n[0] - (g[0] - along * n[0]);
      contacts_.jy[k] = lambda * n[1] - (g[1] - along * n[1]);
      contacts_.jz[k] = lambda * n[2] - (g[2] - along * n[2]);
      ++f.warm;
    }
  }

  // collide: one schedule for this step's contacts, several passes over
  // it in one solve, each writing v and w into the records in place.
  const auto s0 = std::chrono::steady_clock::now();
  schedule_.build(view, bodies);  // inverse masses read from the records
  f.stats = solver_.solve(bodies, view, impulses, schedule_);
  f.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
  // J sums the passes (or is each contact's total): the contacts that got
  // an impulse in some pass.
  for (std::size_t k = 0; k < contacts_.size(); ++k) {
    f.resolved += contacts_.jx[k] != 0 || contacts_.jy[k] != 0 || contacts_.jz[k] != 0 ? 1 : 0;
  }
  if (o.warm_start) {
    last_j_.clear();
    for (std::size_t k = 0; k < contacts_.size(); ++k) {
      const Real n[3] = {contacts_.nx[k], contacts_.ny[k], contacts_.nz[k]};
      const Real j[3] = {contacts_.jx[k], contacts_.jy[k], contacts_.jz[k]};
      const Real lambda = std::max(j[0] * n[0] + j[1] * n[1] + j[2] * n[2], Real(0));
      last_j_[pair_key(contacts_.a[k], contacts_.b[k])] = {
          lambda, {lambda * n[0] - j[0], lambda * n[1] - j[1], lambda * n[2] - j[2]}};
    }
  }

  double max_depth = 0, sum_depth = 0;
  for (const Real d : contacts_.depth) {
    max_depth = std::max<double>(max_depth, d);
    sum_depth += d;
  }
  f.max_depth = max_depth;
  f.mean_depth = contacts_.size() > 0 ? sum_depth / static_cast<double>(contacts_.size()) : 0;
  f.lifted = correct_positions(world, contacts_);
  const Real dt = static_cast<Real>(o.dt);
  for (std::size_t i = 1; i < world.size(); ++i) {
    Body& b = world.bodies[i];
    b.p[0] += b.v[0] * dt;
    b.p[1] += b.v[1] * dt;
    b.p[2] += b.v[2] * dt;
  }
  return f;
}

}  // namespace debris
