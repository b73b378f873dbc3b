// hard_scenes/shared_bodies.cpp - the hard scenes whose contacts share bodies
// (collide/eval/hard_scenes.hpp): Newton's cradles, stars and a dense
// cluster.
//
// Design notes
// ------------
// * Apart from the pair families: here a body is in several contacts, so
//   each impulse changes what the next contact of that body sees, and the
//   order and the batching of the contacts matter where for pairs they do
//   not. The scenes have fixed sizes (build_hard_scene), not a count of
//   pairs.
// * The bodies are drawn and shaped as the pairs' are (random_body, shape),
//   then placed on purpose: a cradle's normals pass through both centres, a
//   star's satellites fly at the hub, the cluster's contacts join every
//   pair of bodies closer than its reach.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "hard_scenes/draws.hpp"

namespace collide::hard {
namespace {

using detail::narrow;
using hard_detail::norm;
using hard_detail::perpendicular;
using hard_detail::scaled;
using hard_detail::shape;
using hard_detail::V3;

}  // namespace

template <class T>
SceneRecords<T> cradle_scene(std::size_t longest, const V3& axis, bool elastic, bool equal_masses, bool reversed,
                             std::uint64_t seed) {
  SceneRng rng(seed);
  SceneRecords<T> s;
  for (std::size_t n = 2; n <= longest; ++n) {
    const auto first = static_cast<BodyIndex>(s.bodies.size());
    const double radius = rng.uniform(0.05, 0.5);
    const double mass = rng.log_uniform(0.1, 10);
    const double v0 = rng.uniform(0.5, 5);
    // Cradles 10 m apart across the axis, so that they never touch.
    const V3 origin = scaled(perpendicular(rng, axis), 10.0 * double(n));
    for (std::size_t i = 0; i < n; ++i) {
      BodyRecord<double> b;
      b.m = equal_masses ? mass : rng.log_uniform(0.1, 10);
      b.I[0] = b.I[1] = b.I[2] = 0.4 * b.m * radius * radius;
      for (int d = 0; d < 3; ++d) {
        b.p[d] = origin[d] + 2 * radius * double(i) * axis[d];
        b.v[d] = i == 0 ? v0 * axis[d] : 0;
      }
      s.bodies.push_back(narrow<T>(b));
    }
    std::vector<ContactRecord<T>> chain;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      ContactRecord<double> c;
      c.a = first + static_cast<BodyIndex>(i + 1);
      c.b = first + static_cast<BodyIndex>(i);
      for (int d = 0; d < 3; ++d) {
        c.c[d] = origin[d] + (2 * double(i) + 1) * radius * axis[d];
        c.n[d] = axis[d];
      }
      c.e = elastic ? 1 : rng.uniform(0, 1);
      c.mu = 0;
      chain.push_back(narrow<T>(c));
    }
    if (reversed) std::reverse(chain.begin(), chain.end());
    s.contacts.insert(s.contacts.end(), chain.begin(), chain.end());
  }
  return s;
}

template <class T>
SceneRecords<T> star_scene(std::size_t spokes, bool fixed_hub, Model fit, std::uint64_t seed) {
  SceneRng rng(seed);
  SceneRecords<T> s;
  BodyRecord<double> hub = random_body<double>(rng, {0, 0, 0});
  hub.m *= 10;
  for (double& i : hub.I) i *= 10;
  shape(hub, fit, rng);
  if (fixed_hub) hub.m = std::numeric_limits<double>::infinity();
  const double hub_radius = 1.0;
  s.bodies.push_back(narrow<T>(hub));
  for (std::size_t k = 0; k < spokes; ++k) {
    const V3 d = rng.unit_vector();
    const double radius = rng.uniform(0.05, 0.3);
    BodyRecord<double> sat = random_body<double>(rng, scaled(d, hub_radius + radius));
    shape(sat, fit, rng);
    const double speed = rng.uniform(0.5, 5);
    for (int i = 0; i < 3; ++i) sat.v[i] = -speed * d[i] + rng.uniform(-1, 1);
    s.bodies.push_back(narrow<T>(sat));
    ContactRecord<double> c;
    c.a = static_cast<BodyIndex>(k + 1);
    c.b = 0;
    for (int i = 0; i < 3; ++i) {
      c.c[i] = hub_radius * d[i];
      c.n[i] = d[i];
    }
    c.e = rng.uniform(0, 1);
    c.mu = k % 2 == 0 ? rng.uniform(0, 1) : 0;
    s.contacts.push_back(narrow<T>(c));
  }
  return s;
}

template <class T>
SceneRecords<T> cluster_scene(std::size_t count, double reach, Model fit, std::uint64_t seed) {
  SceneRng rng(seed);
  SceneRecords<T> s;
  std::vector<BodyRecord<double>> bodies;
  for (std::size_t i = 0; i < count; ++i) {
    bodies.push_back(random_body<double>(rng, rng.in_box(1)));
    shape(bodies.back(), fit, rng);
    s.bodies.push_back(narrow<T>(bodies.back()));
  }
  std::vector<ContactRecord<T>> contacts;
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t j = i + 1; j < count; ++j) {
      const V3 d{bodies[i].p[0] - bodies[j].p[0], bodies[i].p[1] - bodies[j].p[1], bodies[i].p[2] - bodies[j].p[2]};
      const double len = norm(d);
      if (len > reach || len == 0) continue;
      ContactRecord<double> c;
      c.a = static_cast<BodyIndex>(i);
      c.b = static_cast<BodyIndex>(j);
      for (int x = 0; x < 3; ++x) {
        c.c[x] = (bodies[i].p[x] + bodies[j].p[x]) / 2;
        c.n[x] = d[x] / len;
      }
      c.e = rng.uniform(0, 1);
      c.mu = rng.chance(0.5) ? rng.uniform(0, 1) : 0;
      contacts.push_back(narrow<T>(c));
    }
  }
  for (std::size_t k = contacts.size(); k > 1; --k) std::swap(contacts[k - 1], contacts[rng.index(k)]);
  s.contacts = contacts;
  return s;
}

#define COLLIDE_SHARED_BODIES(T)                                                                        \
  template SceneRecords<T> cradle_scene<T>(std::size_t, const std::array<double, 3>&, bool, bool, bool, \
                                           std::uint64_t);                                              \
  template SceneRecords<T> star_scene<T>(std::size_t, bool, Model, std::uint64_t);                      \
  template SceneRecords<T> cluster_scene<T>(std::size_t, double, Model, std::uint64_t);
COLLIDE_SHARED_BODIES(float)
COLLIDE_SHARED_BODIES(double)
#undef COLLIDE_SHARED_BODIES

}  // namespace collide::hard
