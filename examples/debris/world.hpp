// world.hpp - the bodies of collide_debris: the ground, the spheres and the
// particles in collide's packed records, the side arrays collide does not
// read, the cloud they start in and their energy.
//
// Design notes
// ------------
// * The records are the simulation's state for the whole run (debris.cpp
//   says why packed): every other part of the example reads and writes them
//   in place, so the world is a struct of them and its side arrays, not a
//   class that hides them.
// * Body 0 is the ground, the plane z = 0 (immovable: inverse mass 0); the
//   other parts skip it by starting at body 1.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include <collide/packed.hpp>

#include "options.hpp"

namespace debris {

using Real = float;                        // what collide solves in: 8 lanes with AVX2, 16 with AVX-512
using Body = collide::PackedSphere<Real>;  // v, w, p, inverse mass, inverse inertia
inline constexpr double kGravity = 9.81;

struct World {
  collide::PackedBuffer<Body> bodies;  // the state collide reads, and v, w it writes
  std::vector<Real> radius;            // [m]
  std::vector<double> mass, inertia;   // [kg], [kg m^2], for the energy
  std::size_t spheres = 0;             // bodies 1..spheres are spheres, the rest particles

  [[nodiscard]] std::size_t size() const { return bodies.size(); }

  void add(double m, double moment, double r, double x, double y, double z) {
    Body body{};  // at rest
    body.p[0] = static_cast<Real>(x);
    body.p[1] = static_cast<Real>(y);
    body.p[2] = static_cast<Real>(z);
    body.inv_mass = std::isinf(m) ? Real(0) : static_cast<Real>(1 / m);
    body.inv_inertia = std::isinf(moment) ? Real(0) : static_cast<Real>(1 / moment);
    bodies.push_back(body);
    radius.push_back(static_cast<Real>(r));
    mass.push_back(m);
    inertia.push_back(moment);
  }

  /// The records as collide sees them; nothing is copied.
  collide::PackedView<Body> view() { return collide::packed_view(bodies); }
};

/// Spheres and particles on a jittered lattice above the ground, shuffled so
/// that both kinds are everywhere in the cloud, with small random velocities.
World make_world(const Options& o);

struct Energy {
  double kinetic = 0, rotational = 0, potential = 0;
  [[nodiscard]] double total() const { return kinetic + rotational + potential; }
};

/// Kinetic, rotational and potential (m g z) energy of the movable bodies, in
/// double.
Energy energy(const World& w);

}  // namespace debris
