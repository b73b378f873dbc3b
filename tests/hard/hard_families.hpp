// tests/hard/hard_families.hpp - the hard-case scene families of issue 6, as
// pure functions of (count, body model to fit, seed).
//
// Why a header of its own: the same scenes feed the tests
// (test_hard_pairs.cpp, test_hard_shared.cpp) and the fixture generator
// (make_fixtures.cpp, which writes data/hard/), so it uses no GoogleTest.
//
// Every family is drawn in double with tests/support/scenes.hpp's Rng and
// body builder, then stored in T (float or double) through BodyRecord<T>: the
// scene the kernel sees is the rounded one, and anything a family promises
// (approaching, exactly resting, a mass ratio reached) is established on the
// stored T values, evaluated in long double.
//
// Each body is shaped for one body model (collide/model.hpp):
//   Fit::particle - infinite moments and w = 0 (particle, sphere and rigid fit);
//   Fit::sphere   - three equal moments (sphere and rigid fit);
//   Fit::rigid    - anisotropic moments, random orientation (rigid only).
// Pair families put pair k on bodies 2k and 2k+1; every other pair has a and
// b swapped so that the SIMD path runs both its paired-load and its gather
// layout on the hard values.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/model.hpp"
#include "collide/reference.hpp"
#include "collide/scene.hpp"
#include "support/scenes.hpp"

namespace collide::hard {

using test::Rng;
using test::SceneRecords;
using L = long double;
using V3 = std::array<double, 3>;

enum class Fit { particle, sphere, rigid };

inline const char* to_string(Fit fit) {
  return fit == Fit::particle ? "particle" : fit == Fit::sphere ? "sphere" : "rigid";
}
/// The cheapest model a scene shaped for `fit` runs (what choose_model must say).
inline Model model_of(Fit fit) {
  return fit == Fit::particle ? Model::particle : fit == Fit::sphere ? Model::sphere : Model::rigid;
}

inline V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline V3 scaled(const V3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double norm(const V3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
/// A random unit vector perpendicular to unit d.
inline V3 perpendicular(Rng& rng, const V3& d) {
  for (;;) {
    const V3 t = cross(d, rng.unit_vector());
    const double len = norm(t);
    if (len > 1e-3) return scaled(t, 1 / len);
  }
}
/// 10^x for x uniform in [lo, hi]; every `every`-th draw (k % every == 0) is
/// pinned to `pin`, so the extreme a family promises is always in the scene.
inline double decade(Rng& rng, double lo, double hi, std::size_t k, std::size_t every, double pin) {
  const double x = rng.uniform(lo, hi);
  return std::pow(10.0, k % every == 0 ? pin : x);
}

/// Gives a body the moments and spin of `fit`, keeping its mass.
inline void shape(BodyRecord<double>& b, Fit fit, Rng& rng) {
  const double inf = std::numeric_limits<double>::infinity();
  if (fit == Fit::particle) {
    b.I[0] = b.I[1] = b.I[2] = inf;
    b.w[0] = b.w[1] = b.w[2] = 0;
  } else if (fit == Fit::sphere) {
    const double r = rng.uniform(0.2, 1.5);
    b.I[0] = b.I[1] = b.I[2] = b.m * r * r;
  }
}

/// Largest radius of gyration sqrt(I/m) of a body [m].
inline double gyration_radius(const BodyRecord<double>& b) {
  return std::sqrt(std::max({b.I[0], b.I[1], b.I[2]}) / b.m);
}

/// One pair as drawn: body a, body b, the contact (indices set when stored).
struct Pair {
  BodyRecord<double> a, b;
  ContactRecord<double> c;
};

/// The support builders' pair (random masses, moments, orientations,
/// velocities; centres 0.1 to 1.5 m from the contact point), shaped for `fit`.
inline Pair base_pair(Rng& rng, Fit fit, bool friction) {
  test::SceneOptions o;
  o.friction = friction;
  const V3 c = rng.in_box(5);
  auto centre = [&] {
    const V3 d = rng.unit_vector();
    return add(c, scaled(d, -rng.uniform(0.1, 1.5)));
  };
  Pair p;
  p.a = test::random_body<double>(rng, centre());
  p.b = test::random_body<double>(rng, centre());
  shape(p.a, fit, rng);
  shape(p.b, fit, rng);
  p.c = test::random_contact<double>(rng, o, 0, 1, c);
  return p;
}

template <class T>
BodyRecord<T> stored(const BodyRecord<double>& b) {
  BodyRecord<T> r;
  r.m = static_cast<T>(b.m);
  for (int i = 0; i < 3; ++i) {
    r.I[i] = static_cast<T>(b.I[i]);
    r.p[i] = static_cast<T>(b.p[i]);
    r.v[i] = static_cast<T>(b.v[i]);
    r.w[i] = static_cast<T>(b.w[i]);
  }
  for (int i = 0; i < 4; ++i) r.q[i] = static_cast<T>(b.q[i]);
  return r;
}

template <class T>
ContactRecord<T> stored(const ContactRecord<double>& c) {
  ContactRecord<T> r;
  r.a = c.a;
  r.b = c.b;
  for (int i = 0; i < 3; ++i) {
    r.c[i] = static_cast<T>(c.c[i]);
    r.n[i] = static_cast<T>(c.n[i]);
  }
  r.e = static_cast<T>(c.e);
  r.mu = static_cast<T>(c.mu);
  return r;
}

/// Relative velocity of a's contact point with respect to b's, in long double
/// from stored values.
template <class T>
std::array<L, 3> relative_velocity(const BodyRecord<T>& a, const BodyRecord<T>& b, const ContactRecord<T>& c) {
  std::array<L, 3> u{};
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const L raj = L(c.c[j]) - L(a.p[j]), rak = L(c.c[k]) - L(a.p[k]);
    const L rbj = L(c.c[j]) - L(b.p[j]), rbk = L(c.c[k]) - L(b.p[k]);
    u[i] = (L(a.v[i]) + (L(a.w[j]) * rak - L(a.w[k]) * raj)) - (L(b.v[i]) + (L(b.w[j]) * rbk - L(b.w[k]) * rbj));
  }
  return u;
}

/// Appends pair k in T: side a is body 2k and side b body 2k+1 for even k,
/// the other way round for odd k (the SIMD path's gather layout).
template <class T>
void push_pair(SceneRecords<T>& s, const BodyRecord<T>& a, const BodyRecord<T>& b, ContactRecord<T> c) {
  const auto k = static_cast<BodyIndex>(s.contacts.size());
  const bool swap = k % 2 == 1;
  s.bodies.push_back(swap ? b : a);
  s.bodies.push_back(swap ? a : b);
  c.a = swap ? 2 * k + 1 : 2 * k;
  c.b = swap ? 2 * k : 2 * k + 1;
  s.contacts.push_back(c);
}

/// Stores a drawn pair in T, made approaching on the stored values.
template <class T>
void push_approaching(SceneRecords<T>& s, const Pair& p) {
  const BodyRecord<T> a = stored<T>(p.a), b = stored<T>(p.b);
  ContactRecord<T> c = stored<T>(p.c);
  test::make_approach(a, b, c);
  push_pair(s, a, b, c);
}

// ---------------------------------------------------------------------------
// Pair families. Each returns `count` independent pairs.
// ---------------------------------------------------------------------------

/// Pairs drawn by base_pair (friction where `friction(k)`), changed by
/// `modify(rng, k, pair)` and stored approaching: the skeleton most pair
/// families share.
inline bool odd(std::size_t k) { return k % 2 == 1; }
template <class T, class Modify, class Friction = bool (*)(std::size_t)>
SceneRecords<T> approaching_pairs(std::size_t count, Fit fit, std::uint64_t seed, Modify modify,
                                  Friction friction = odd) {
  Rng rng(seed);
  SceneRecords<T> s;
  for (std::size_t k = 0; k < count; ++k) {
    Pair p = base_pair(rng, fit, friction(k));
    modify(rng, k, p);
    push_approaching(s, p);
  }
  return s;
}

/// Mass ratios m_b / m_a = 10^x, x uniform in [-8, 8] (every 25th pinned to
/// +-8); b's moments scale with its mass.
template <class T>
SceneRecords<T> mass_ratio_family(std::size_t count, Fit fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](Rng& rng, std::size_t k, Pair& p) {
    const double ratio = decade(rng, -8, 8, k, 25, (k / 25) % 2 == 0 ? 8 : -8);
    p.b.m *= ratio;
    for (double& i : p.b.I) i *= ratio;
  });
}

/// Which side of an immovable-family pair is immovable: pair k has kind k % 3.
enum class Immovable { a, b, both };
inline Immovable immovable_kind(std::size_t k) { return static_cast<Immovable>(k % 3); }

/// An immovable body (m = inf) on side a, side b or both. Its moments are
/// finite or inf (alternately); it moves kinematically (v, and w unless the
/// scene is for particles).
template <class T>
SceneRecords<T> immovable_family(std::size_t count, Fit fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](Rng&, std::size_t k, Pair& p) {
    const double inf = std::numeric_limits<double>::infinity();
    const Immovable kind = immovable_kind(k);
    for (BodyRecord<double>* b : {&p.a, &p.b}) {
      const bool fixed = kind == Immovable::both || (kind == Immovable::a) == (b == &p.a);
      if (!fixed) continue;
      b->m = inf;
      if ((k / 3) % 2 == 0) b->I[0] = b->I[1] = b->I[2] = inf;
    }
  });
}

/// Needle-thin body a (rigid only): moments I_y = I_z = m L^2 / 3 of a rod of
/// half-length L, I_x = I_y * 10^x with x in [-12, -3] (every 25th pinned to
/// -12), random orientation, struck at a tip: c = p + R (+-L, 0, 0). Body b is
/// an ordinary rigid body, immovable in every fourth pair.
template <class T>
SceneRecords<T> needle_family(std::size_t count, std::uint64_t seed) {
  return approaching_pairs<T>(count, Fit::rigid, seed, [](Rng& rng, std::size_t k, Pair& p) {
    BodyRecord<double>& a = p.a;
    const double half = rng.uniform(0.5, 2.0);
    a.I[1] = a.I[2] = a.m * half * half / 3;
    a.I[0] = a.I[1] * decade(rng, -12, -3, k, 25, -12);
    // The tip in the world frame: the body's x axis is the first column of R.
    const double qw = a.q[0], qx = a.q[1], qy = a.q[2], qz = a.q[3];
    const V3 axis{1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy + qw * qz), 2 * (qx * qz - qw * qy)};
    const double side = rng.chance(0.5) ? half : -half;
    const V3 c = add({a.p[0], a.p[1], a.p[2]}, scaled(axis, side));
    for (int i = 0; i < 3; ++i) p.c.c[i] = c[i];
    const V3 d = rng.unit_vector();
    for (int i = 0; i < 3; ++i) p.b.p[i] = c[i] + rng.uniform(0.1, 1.5) * d[i];
    if (k % 4 == 3) p.b.m = std::numeric_limits<double>::infinity();
  });
}

/// Long levers: the contact point |r| = rho * 10^x from a's centre, x in
/// [0, 4] (every 25th pinned to 4), rho a's largest radius of gyration. In
/// every fourth pair the normal is within 10^-6..10^-1 rad of r, so that
/// r x n is small and cancels (the case docs/collision-law.md calls out),
/// and neither body spins, so that w x r does not dominate the speed scale.
template <class T>
SceneRecords<T> long_lever_family(std::size_t count, Fit fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](Rng& rng, std::size_t k, Pair& p) {
    const double lever = gyration_radius(p.a) * decade(rng, 0, 4, k, 25, 4);
    const V3 d = rng.unit_vector();
    const V3 c{p.c.c[0], p.c.c[1], p.c.c[2]};
    for (int i = 0; i < 3; ++i) p.a.p[i] = c[i] - lever * d[i];
    if (k % 4 == 1) {
      const V3 n = add(d, scaled(perpendicular(rng, d), std::pow(10.0, rng.uniform(-6, -1))));
      const double len = norm(n);
      for (int i = 0; i < 3; ++i) {
        p.c.n[i] = n[i] / len;
        p.a.w[i] = p.b.w[i] = 0;
      }
    }
  });
}

/// Grazing approach: the relative velocity is set (through v_a) so that
/// vn / |u| = -10^x, x in [-7, 0] (every 25th pinned to -7), in long double
/// from the stored values; the rounding of v_a to T then moves the ratio by
/// up to eps(T) |v_a| / |u|. Half of the pairs have friction.
template <class T>
SceneRecords<T> grazing_family(std::size_t count, Fit fit, std::uint64_t seed) {
  Rng rng(seed);
  SceneRecords<T> s;
  for (std::size_t k = 0; k < count; ++k) {
    const Pair p = base_pair(rng, fit, k % 2 == 1);
    BodyRecord<T> a = stored<T>(p.a);
    const BodyRecord<T> b = stored<T>(p.b);
    ContactRecord<T> c = stored<T>(p.c);
    const double ratio = decade(rng, -7, 0, k, 25, -7);
    const V3 n{double(c.n[0]), double(c.n[1]), double(c.n[2])};
    const V3 t = perpendicular(rng, n);
    const double speed = rng.uniform(1, 5);
    const std::array<L, 3> u = relative_velocity(a, b, c);
    for (int i = 0; i < 3; ++i) {
      const L target = L(speed) * (L(t[i]) - L(ratio) * L(n[i]));
      a.v[i] = static_cast<T>(L(a.v[i]) + (target - u[i]));
    }
    test::make_approach(a, b, c);
    push_pair(s, a, b, c);
  }
  return s;
}

/// Unit scales: length, mass and speed scales 10^x each, x in [-5, 5]
/// independently (every 25th pair at a corner of the cube):
/// m *= M, I *= M L^2, p, c *= L, v *= V, w *= V / L.
template <class T>
SceneRecords<T> unit_scale_family(std::size_t count, Fit fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](Rng& rng, std::size_t k, Pair& p) {
    const std::size_t corner = k / 25;
    const double len = decade(rng, -5, 5, k, 25, corner & 1 ? 5 : -5);
    const double mass = decade(rng, -5, 5, k, 25, corner & 2 ? 5 : -5);
    const double speed = decade(rng, -5, 5, k, 25, corner & 4 ? 5 : -5);
    for (BodyRecord<double>* b : {&p.a, &p.b}) {
      b->m *= mass;
      for (int i = 0; i < 3; ++i) {
        b->I[i] *= mass * len * len;
        b->p[i] *= len;
        b->v[i] *= speed;
        b->w[i] *= speed / len;
      }
    }
    for (double& x : p.c.c) x *= len;
  });
}

/// Subnormal speeds (meant for float): every component of v and w is
/// +-10^x, x in [-45.5, -38] (float's subnormals are 1.4e-45 .. 1.2e-38);
/// masses, moments and lengths are ordinary.
template <class T>
SceneRecords<T> subnormal_family(std::size_t count, Fit fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [fit](Rng& rng, std::size_t, Pair& p) {
    for (BodyRecord<double>* b : {&p.a, &p.b}) {
      for (int i = 0; i < 3; ++i) {
        const double sign = rng.chance(0.5) ? 1 : -1;
        b->v[i] = sign * std::pow(10.0, rng.uniform(-45.5, -38));
        if (fit != Fit::particle) b->w[i] = -sign * std::pow(10.0, rng.uniform(-45.5, -38));
      }
    }
  });
}

/// Exactly separating (even k: vn > 0.01 S, far from any rounding) and exactly
/// resting (odd k: vn == 0 in every precision) contacts. A resting contact
/// has an axis normal +-e_i, equal v_i on both bodies, and each body's w
/// either parallel to n or its lever arm r parallel to n, with the other
/// components exactly 0, so that every product in (w x r) . n is an exact
/// zero in T and in long double alike.
template <class T>
SceneRecords<T> separating_resting_family(std::size_t count, Fit fit, std::uint64_t seed) {
  Rng rng(seed);
  SceneRecords<T> s;
  for (std::size_t k = 0; k < count; ++k) {
    Pair p = base_pair(rng, fit, (k / 2) % 2 == 0);
    if (k % 2 == 0) {
      for (;;) {
        BodyRecord<T> a = stored<T>(p.a), b = stored<T>(p.b);
        ContactRecord<T> c = stored<T>(p.c);
        const std::array<L, 3> u = relative_velocity(a, b, c);
        const L vn = u[0] * L(c.n[0]) + u[1] * L(c.n[1]) + u[2] * L(c.n[2]);
        const L speed = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        if (std::abs(vn) > L(0.01) * speed) {
          if (vn < 0) {
            for (T& x : c.n) x = -x;
          }
          push_pair(s, a, b, c);
          break;
        }
        p = base_pair(rng, fit, true);
      }
      continue;
    }
    const int axis = static_cast<int>(rng.index(3));
    const double sign = rng.chance(0.5) ? 1 : -1;
    for (int i = 0; i < 3; ++i) p.c.n[i] = i == axis ? sign : 0;
    BodyRecord<T> a = stored<T>(p.a), b = stored<T>(p.b);
    ContactRecord<T> c = stored<T>(p.c);
    b.v[axis] = a.v[axis];
    for (BodyRecord<T>* body : {&a, &b}) {
      // Either w parallel to n (particles have no spin at all) or r parallel
      // to n, for all the body's components at once.
      const bool spin_along_n = fit == Fit::particle || rng.chance(0.5);
      for (int i = 0; i < 3; ++i) {
        if (i == axis) continue;
        if (spin_along_n) {
          body->w[i] = 0;
        } else {
          body->p[i] = c.c[i];
        }
      }
    }
    push_pair(s, a, b, c);
  }
  return s;
}

/// Restitution at its ends: e = 0 and e = 1, each with and without friction
/// (pair k: e = k % 2, friction when k % 4 >= 2).
template <class T>
SceneRecords<T> restitution_family(std::size_t count, Fit fit, std::uint64_t seed) {
  return approaching_pairs<T>(
      count, fit, seed, [](Rng&, std::size_t k, Pair& p) { p.c.e = static_cast<double>(k % 2); },
      [](std::size_t k) { return k % 4 >= 2; });
}

/// Friction at the stick/slip boundary: mu is set so that mu jn equals the
/// sticking impulse |ut| / K(t) of the long double reference, times
/// (1 + d) with d = 0 (every fifth pair) or +-10^x, x in [-8, -1]: the
/// contacts sit on both sides of the min() in jt = min(|ut|/K(t), mu jn).
template <class T>
SceneRecords<T> stick_slip_family(std::size_t count, Fit fit, std::uint64_t seed) {
  // mu = 1e6 sticks: the reference then reports the sticking impulse as jt.
  SceneRecords<T> s = approaching_pairs<T>(
      count, fit, seed, [](Rng&, std::size_t, Pair& p) { p.c.mu = 1e6; }, [](std::size_t) { return true; });
  Rng rng(seed + 1);
  Scene<L> probe = convert_scene<L>(s.scene());
  ImpulseBuffer<L> j(count);
  std::vector<ReferenceContact<L>> diag(count);
  reference_solve<L>(probe.bodies.view(), probe.contacts.view(), j.view(), diag.data());
  for (std::size_t k = 0; k < count; ++k) {
    const double x = rng.uniform(-8, -1);
    const L d = k % 5 == 0 ? L(0) : (rng.chance(0.5) ? L(1) : L(-1)) * std::pow(L(10), L(x));
    const L mu = diag[k].jn > 0 ? diag[k].jt / diag[k].jn * (1 + d) : L(0.5);
    s.contacts[k].mu = static_cast<T>(mu);
  }
  return s;
}

/// Spin-dominated contacts: |w| = 10^x rad/s, x in [1, 4], and each body's
/// |v| = 10^y |w| |r|, y in [-6, -2]: the relative velocity is almost all
/// w x r.
template <class T>
SceneRecords<T> spin_family(std::size_t count, Fit fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](Rng& rng, std::size_t, Pair& p) {
    for (BodyRecord<double>* b : {&p.a, &p.b}) {
      const V3 r{p.c.c[0] - b->p[0], p.c.c[1] - b->p[1], p.c.c[2] - b->p[2]};
      const double spin = std::pow(10.0, rng.uniform(1, 4));
      const V3 w = scaled(rng.unit_vector(), spin);
      const V3 v = scaled(rng.unit_vector(), spin * norm(r) * std::pow(10.0, rng.uniform(-6, -2)));
      for (int i = 0; i < 3; ++i) {
        b->w[i] = w[i];
        b->v[i] = v[i];
      }
    }
  });
}

// ---------------------------------------------------------------------------
// Shared-body families.
// ---------------------------------------------------------------------------

/// Newton's cradles of 2 .. `longest` solid spheres (I = 2/5 m R^2, no spin),
/// one after another in one scene. Each cradle lies along `axis` (unit),
/// sphere i at distance 2 R i from the first, and only the first one moves
/// (speed v0 along the axis). Contact i of a cradle joins sphere i+1 (a) and
/// sphere i (b) at their touching point with n = axis, frictionless; e is 1
/// when `elastic`, else uniform in [0, 1]. Masses are equal inside a cradle
/// when `equal_masses`, otherwise log-uniform in [0.1, 10]. With an
/// axis-aligned `axis` every normal passes exactly through both centres, so
/// the particle model fits (its second rule); otherwise the sphere model is
/// the cheapest. `reversed` lists each cradle's contacts last to first.
template <class T>
SceneRecords<T> cradle_scene(std::size_t longest, const V3& axis, bool elastic, bool equal_masses, bool reversed,
                             std::uint64_t seed) {
  Rng rng(seed);
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
      s.bodies.push_back(stored<T>(b));
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
      chain.push_back(stored<T>(c));
    }
    if (reversed) std::reverse(chain.begin(), chain.end());
    s.contacts.insert(s.contacts.end(), chain.begin(), chain.end());
  }
  return s;
}

/// A star: body 0, the hub, in `spokes` contacts, one with each satellite
/// (bodies 1 .. spokes), which sit around it in random directions and fly
/// at it. Contact k joins satellite k+1 (a) and the hub (b), n from the hub
/// towards the satellite. The hub is immovable when `fixed_hub`, otherwise
/// 10 times as heavy as a satellite on average. e uniform in [0, 1];
/// friction in half of the contacts.
template <class T>
SceneRecords<T> star_scene(std::size_t spokes, bool fixed_hub, Fit fit, std::uint64_t seed) {
  Rng rng(seed);
  SceneRecords<T> s;
  BodyRecord<double> hub = test::random_body<double>(rng, {0, 0, 0});
  hub.m *= 10;
  for (double& i : hub.I) i *= 10;
  shape(hub, fit, rng);
  if (fixed_hub) hub.m = std::numeric_limits<double>::infinity();
  const double hub_radius = 1.0;
  s.bodies.push_back(stored<T>(hub));
  for (std::size_t k = 0; k < spokes; ++k) {
    const V3 d = rng.unit_vector();
    const double radius = rng.uniform(0.05, 0.3);
    BodyRecord<double> sat = test::random_body<double>(rng, scaled(d, hub_radius + radius));
    shape(sat, fit, rng);
    const double speed = rng.uniform(0.5, 5);
    for (int i = 0; i < 3; ++i) sat.v[i] = -speed * d[i] + rng.uniform(-1, 1);
    s.bodies.push_back(stored<T>(sat));
    ContactRecord<double> c;
    c.a = static_cast<BodyIndex>(k + 1);
    c.b = 0;
    for (int i = 0; i < 3; ++i) {
      c.c[i] = hub_radius * d[i];
      c.n[i] = d[i];
    }
    c.e = rng.uniform(0, 1);
    c.mu = k % 2 == 0 ? rng.uniform(0, 1) : 0;
    s.contacts.push_back(stored<T>(c));
  }
  return s;
}

/// A dense cluster: `count` bodies in a 2 m box, a contact for every pair
/// closer than `reach` (at the midpoint, n along the line of centres, from b
/// towards a), listed in random order. Velocities random, so some contacts
/// approach and some separate, and a body is in many contacts. e uniform in
/// [0, 1], friction in half of the contacts. No immovable body, so momentum
/// is conserved.
template <class T>
SceneRecords<T> cluster_scene(std::size_t count, double reach, Fit fit, std::uint64_t seed) {
  Rng rng(seed);
  SceneRecords<T> s;
  std::vector<BodyRecord<double>> bodies;
  for (std::size_t i = 0; i < count; ++i) {
    bodies.push_back(test::random_body<double>(rng, rng.in_box(1)));
    shape(bodies.back(), fit, rng);
    s.bodies.push_back(stored<T>(bodies.back()));
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
      contacts.push_back(stored<T>(c));
    }
  }
  for (std::size_t k = contacts.size(); k > 1; --k) std::swap(contacts[k - 1], contacts[rng.index(k)]);
  s.contacts = contacts;
  return s;
}

}  // namespace collide::hard
