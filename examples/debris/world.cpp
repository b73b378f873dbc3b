// world.cpp - the set-up of collide_debris's bodies and their energy
// (world.hpp).
//
// Design notes
// ------------
// * The cloud is drawn from the seed alone (std::mt19937_64 and libstdc++'s
//   distributions), so that both solve orders start from the same world and
//   a run can be repeated.
#include "world.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <random>
#include <vector>

namespace debris {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDensity = 1000;  // [kg/m^3]
constexpr double kSphereRadius[2] = {0.05, 0.10};
constexpr double kParticleRadius = 0.025;

}  // namespace

World make_world(const Options& o) {
  const double inf = std::numeric_limits<double>::infinity();
  World world;
  world.add(inf, inf, 0, 0, 0, 0);  // the ground
  const int n = o.spheres + o.particles;
  std::vector<int> kind(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) kind[static_cast<std::size_t>(i)] = i < o.spheres ? 0 : 1;
  std::mt19937_64 rng(o.seed);
  std::shuffle(kind.begin(), kind.end(), rng);
  std::uniform_real_distribution<double> unit(0, 1);

  // A square block of lattice sites; a site holds the largest sphere.
  const double spacing = 2 * kSphereRadius[1] * 1.1;
  // About 1.6 n^(1/3) sites a side: a cloud a few times wider than tall, so
  // bodies land on the ground and on each other at a few m/s.
  const int side = std::max(1, static_cast<int>(1.6 * std::cbrt(n)));
  world.spheres = static_cast<std::size_t>(o.spheres);
  // Spheres first (ids 1..spheres), then particles: sites come from `kind`.
  std::vector<std::size_t> site_of_body;
  for (int pass = 0; pass < 2; ++pass) {
    for (int s = 0; s < n; ++s) {
      if (kind[static_cast<std::size_t>(s)] != pass) continue;
      const double x = (s % side - 0.5 * (side - 1)) * spacing + 0.1 * spacing * (unit(rng) - 0.5);
      const double y = ((s / side) % side - 0.5 * (side - 1)) * spacing + 0.1 * spacing * (unit(rng) - 0.5);
      const int layer = s / (side * side);
      const double z = kSphereRadius[1] * 1.5 + static_cast<double>(layer) * spacing;
      const double r =
          pass == 0 ? kSphereRadius[0] + (kSphereRadius[1] - kSphereRadius[0]) * unit(rng) : kParticleRadius;
      const double m = kDensity * 4.0 / 3.0 * kPi * r * r * r;
      // A particle has no rotational state: infinite moment, inverse 0.
      const double moment = pass == 0 ? 0.4 * m * r * r : inf;
      world.add(m, moment, r, x, y, z);
      Body& body = world.bodies.bodies.back();
      body.v[0] = static_cast<Real>(0.5 * (unit(rng) - 0.5));
      body.v[1] = static_cast<Real>(0.5 * (unit(rng) - 0.5));
    }
  }
  return world;
}

Energy energy(const World& w) {
  Energy e;
  for (std::size_t i = 1; i < w.size(); ++i) {
    const Body& b = w.bodies[i];
    const double v2 = double(b.v[0]) * b.v[0] + double(b.v[1]) * b.v[1] + double(b.v[2]) * b.v[2];
    const double w2 = double(b.w[0]) * b.w[0] + double(b.w[1]) * b.w[1] + double(b.w[2]) * b.w[2];
    e.kinetic += 0.5 * w.mass[i] * v2;
    if (b.inv_inertia > 0) e.rotational += 0.5 * w.inertia[i] * w2;
    e.potential += w.mass[i] * kGravity * b.p[2];
  }
  return e;
}

}  // namespace debris
