// tests/support/scenes.hpp - small, self-contained random scene builders for
// the kernel tests.
//
// The tests do not depend on the library's generator (generate.cpp): every
// scene here is drawn with std::mt19937_64 from a seed (the draws of
// collide/eval/hard_scenes.hpp, which the hard families share) and pushed through
// the public BodyBuffer / ContactBuffer API, so a test failure can always be
// reproduced from the seed printed with it.
//
// Two shapes of scene:
//   * pairs:  contact k joins bodies 2k and 2k+1; no body is shared, so the
//             whole scene is one contiguous batch;
//   * shared: contacts over fewer movable bodies (random indices, so bodies
//             are shared and contacts chain) plus one immovable ground body,
//             the last body, which is side b of 25% of the contacts.
// Every contact approaches in the initial state (the normal is flipped when
// the drawn one separates); in a shared scene a later contact may of course
// separate after the earlier ones have acted.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/eval/hard_scenes.hpp"
#include "collide/io/scene.hpp"

namespace collide::test {

/// The library's draws (collide/eval/hard_scenes.hpp): the hard families and
/// these scenes are made of the same bodies and contacts.
using Rng = SceneRng;

struct SceneOptions {
  std::uint64_t seed = 1;
  /// mu drawn uniformly from [0, 1] when true; mu = 0 otherwise.
  bool friction = false;
  /// Restitution: < 0 draws e uniformly from [0, 1] per contact; otherwise
  /// every contact gets this value.
  double e = -1;
  /// Half-size of the box the centres of mass (pairs: contact points) lie in [m].
  double box = 5;
};

/// random_contact with the scene options' friction and restitution.
template <class T>
ContactRecord<T> random_contact(Rng& rng, const SceneOptions& o, BodyIndex ia, BodyIndex ib,
                                const std::array<double, 3>& c) {
  return collide::random_contact<T>(rng, ia, ib, c, o.friction, o.e);
}

/// `pairs` independent approaching pairs: contact k joins bodies 2k and 2k+1.
/// The contact point lies in the box, each centre of mass 0.1 to 1.5 m from it.
template <class T>
SceneRecords<T> pairs_records(std::size_t pairs, const SceneOptions& o = {}) {
  Rng rng(o.seed);
  SceneRecords<T> s;
  s.bodies.reserve(2 * pairs);
  s.contacts.reserve(pairs);
  for (std::size_t k = 0; k < pairs; ++k) {
    const auto c = rng.in_box(o.box);
    auto offset = [&] {
      const auto d = rng.unit_vector();
      const double len = rng.uniform(0.1, 1.5);
      return std::array<double, 3>{c[0] - len * d[0], c[1] - len * d[1], c[2] - len * d[2]};
    };
    const BodyRecord<T> a = random_body<T>(rng, offset());
    const BodyRecord<T> b = random_body<T>(rng, offset());
    ContactRecord<T> contact =
        random_contact<T>(rng, o, static_cast<BodyIndex>(2 * k), static_cast<BodyIndex>(2 * k + 1), c);
    make_approach(a, b, contact);
    s.bodies.push_back(a);
    s.bodies.push_back(b);
    s.contacts.push_back(contact);
  }
  return s;
}

template <class T>
Scene<T> pairs_scene(std::size_t pairs, const SceneOptions& o = {}) {
  return pairs_records<T>(pairs, o).scene();
}

/// The immovable ground of shared scenes: m = inf with finite (ignored)
/// moments, a random orientation, and a kinematic velocity.
template <class T>
BodyRecord<T> ground_body(Rng& rng) {
  BodyRecord<T> g;
  g.m = std::numeric_limits<T>::infinity();
  g.I[0] = T(2), g.I[1] = T(3), g.I[2] = T(5);
  const auto q = rng.quaternion();
  for (int i = 0; i < 4; ++i) g.q[i] = static_cast<T>(q[i]);
  g.p[0] = T(0), g.p[1] = T(-6), g.p[2] = T(0);
  for (int i = 0; i < 3; ++i) {
    g.v[i] = static_cast<T>(rng.uniform(-0.5, 0.5));
    g.w[i] = static_cast<T>(rng.uniform(-0.1, 0.1));
  }
  return g;
}

/// `contacts` contacts over `movable` movable bodies plus one immovable ground
/// body (index `movable`, the last one), side b of 25% of the contacts. The
/// contact point lies 0.1 to 1.5 m from a's centre of mass.
template <class T>
SceneRecords<T> shared_records(std::size_t contacts, std::size_t movable, const SceneOptions& o = {}) {
  Rng rng(o.seed);
  SceneRecords<T> s;
  s.bodies.reserve(movable + 1);
  for (std::size_t i = 0; i < movable; ++i) s.bodies.push_back(random_body<T>(rng, rng.in_box(o.box)));
  s.bodies.push_back(ground_body<T>(rng));
  const auto ground = static_cast<BodyIndex>(movable);
  s.contacts.reserve(contacts);
  for (std::size_t k = 0; k < contacts; ++k) {
    const auto ia = static_cast<BodyIndex>(rng.index(movable));
    BodyIndex ib = ground;
    if (!rng.chance(0.25)) {
      do {
        ib = static_cast<BodyIndex>(rng.index(movable));
      } while (ib == ia);
    }
    const auto d = rng.unit_vector();
    const double len = rng.uniform(0.1, 1.5);
    const BodyRecord<T>& a = s.bodies[ia];
    const std::array<double, 3> c{double(a.p[0]) + len * d[0], double(a.p[1]) + len * d[1],
                                  double(a.p[2]) + len * d[2]};
    ContactRecord<T> contact = random_contact<T>(rng, o, ia, ib, c);
    make_approach(a, s.bodies[ib], contact);
    s.contacts.push_back(contact);
  }
  return s;
}

template <class T>
Scene<T> shared_scene(std::size_t contacts, std::size_t movable, const SceneOptions& o = {}) {
  return shared_records<T>(contacts, movable, o).scene();
}

}  // namespace collide::test
