// tests/support/scenes.hpp - small, self-contained random scene builders for
// the kernel tests.
//
// The tests do not depend on the library's generator (generate.cpp): every
// scene here is drawn with std::mt19937_64 from a seed and pushed through the
// public BodyBuffer / ContactBuffer API, so a test failure can always be
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
#include <random>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/scene.hpp"

namespace collide::test {

/// Deterministic random draws (libstdc++'s distributions are fixed for a seed).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : g_(seed) {}

  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g_); }
  double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  std::size_t index(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(g_); }
  bool chance(double p) { return uniform(0, 1) < p; }
  double normal() { return std::normal_distribution<double>(0, 1)(g_); }

  std::array<double, 3> unit_vector() {
    for (;;) {
      const std::array<double, 3> v{normal(), normal(), normal()};
      const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      if (n > 1e-3) return {v[0] / n, v[1] / n, v[2] / n};
    }
  }
  /// Uniformly distributed rotation (normalised 4-D Gaussian).
  std::array<double, 4> quaternion() {
    for (;;) {
      const std::array<double, 4> q{normal(), normal(), normal(), normal()};
      const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (n > 1e-3) return {q[0] / n, q[1] / n, q[2] / n, q[3] / n};
    }
  }
  std::array<double, 3> in_box(double half) {
    return {uniform(-half, half), uniform(-half, half), uniform(-half, half)};
  }

 private:
  std::mt19937_64 g_;
};

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

/// A random movable body at p: mass log-uniform in [0.1, 10] kg, principal
/// moments m r_i^2 with radii of gyration in [0.2, 1.5] m (anisotropy up to
/// ~56), a uniform random orientation, |v_i|, |w_i| <= 5.
template <class T>
BodyRecord<T> random_body(Rng& rng, const std::array<double, 3>& p) {
  BodyRecord<T> b;
  const double m = rng.log_uniform(0.1, 10);
  b.m = static_cast<T>(m);
  for (int i = 0; i < 3; ++i) {
    const double r = rng.uniform(0.2, 1.5);
    b.I[i] = static_cast<T>(m * r * r);
  }
  const auto q = rng.quaternion();
  for (int i = 0; i < 4; ++i) b.q[i] = static_cast<T>(q[i]);
  for (int i = 0; i < 3; ++i) {
    b.p[i] = static_cast<T>(p[i]);
    b.v[i] = static_cast<T>(rng.uniform(-5, 5));
    b.w[i] = static_cast<T>(rng.uniform(-5, 5));
  }
  return b;
}

/// u . n of a contact, in long double from the stored (T) values: the sign
/// the builders use to make a contact approach.
template <class T>
long double approach_speed(const BodyRecord<T>& a, const BodyRecord<T>& b, const ContactRecord<T>& c) {
  using L = long double;
  L ra[3], rb[3], u[3];
  for (int i = 0; i < 3; ++i) {
    ra[i] = L(c.c[i]) - L(a.p[i]);
    rb[i] = L(c.c[i]) - L(b.p[i]);
  }
  auto point_velocity = [](const BodyRecord<T>& body, const L r[3], int i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    return L(body.v[i]) + (L(body.w[j]) * r[k] - L(body.w[k]) * r[j]);
  };
  for (int i = 0; i < 3; ++i) u[i] = point_velocity(a, ra, i) - point_velocity(b, rb, i);
  return u[0] * L(c.n[0]) + u[1] * L(c.n[1]) + u[2] * L(c.n[2]);
}

template <class T>
ContactRecord<T> random_contact(Rng& rng, const SceneOptions& o, BodyIndex ia, BodyIndex ib,
                                const std::array<double, 3>& c) {
  ContactRecord<T> k;
  k.a = ia;
  k.b = ib;
  for (int i = 0; i < 3; ++i) k.c[i] = static_cast<T>(c[i]);
  const auto n = rng.unit_vector();
  for (int i = 0; i < 3; ++i) k.n[i] = static_cast<T>(n[i]);
  k.e = static_cast<T>(o.e < 0 ? rng.uniform(0, 1) : o.e);
  k.mu = static_cast<T>(o.friction ? rng.uniform(0, 1) : 0.0);
  return k;
}

/// Flips n when the contact separates, so that it approaches.
template <class T>
void make_approach(const BodyRecord<T>& a, const BodyRecord<T>& b, ContactRecord<T>& k) {
  if (approach_speed(a, b, k) > 0) {
    for (T& x : k.n) x = -x;
  }
}

/// A scene as records, before it is pushed into buffers: tests that need to
/// splice a scene (insert a pair, poison a value) edit the records, so that
/// every other value goes through push_back exactly once, as in the original.
template <class T>
struct SceneRecords {
  std::vector<BodyRecord<T>> bodies;
  std::vector<ContactRecord<T>> contacts;

  [[nodiscard]] Scene<T> scene() const {
    Scene<T> s;
    s.bodies.reserve(bodies.size());
    s.contacts.reserve(contacts.size());
    for (const auto& b : bodies) s.bodies.push_back(b);
    for (const auto& c : contacts) s.contacts.push_back(c);
    return s;
  }
};

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
