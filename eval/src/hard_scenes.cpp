// hard_scenes.cpp - the hard-case scene families of collide/eval/hard_scenes.hpp
// (documented there) and the draws they are made of.
#include "collide/eval/hard_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "collide/eval/reference.hpp"

namespace collide {

// ---------------------------------------------------------------------------
// Draws.
// ---------------------------------------------------------------------------

double SceneRng::uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g_); }
double SceneRng::log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
std::size_t SceneRng::index(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(g_); }
bool SceneRng::chance(double p) { return uniform(0, 1) < p; }
double SceneRng::normal() { return std::normal_distribution<double>(0, 1)(g_); }

std::array<double, 3> SceneRng::unit_vector() {
  for (;;) {
    const std::array<double, 3> v{normal(), normal(), normal()};
    const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (n > 1e-3) return {v[0] / n, v[1] / n, v[2] / n};
  }
}

std::array<double, 4> SceneRng::quaternion() {
  for (;;) {
    const std::array<double, 4> q{normal(), normal(), normal(), normal()};
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (n > 1e-3) return {q[0] / n, q[1] / n, q[2] / n, q[3] / n};
  }
}

std::array<double, 3> SceneRng::in_box(double half) {
  return {uniform(-half, half), uniform(-half, half), uniform(-half, half)};
}

template <class T>
BodyRecord<T> random_body(SceneRng& rng, const std::array<double, 3>& p) {
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

template <class T>
ContactRecord<T> random_contact(SceneRng& rng, BodyIndex ia, BodyIndex ib, const std::array<double, 3>& c,
                                bool friction, double e) {
  ContactRecord<T> k;
  k.a = ia;
  k.b = ib;
  for (int i = 0; i < 3; ++i) k.c[i] = static_cast<T>(c[i]);
  const auto n = rng.unit_vector();
  for (int i = 0; i < 3; ++i) k.n[i] = static_cast<T>(n[i]);
  k.e = static_cast<T>(e < 0 ? rng.uniform(0, 1) : e);
  k.mu = static_cast<T>(friction ? rng.uniform(0, 1) : 0.0);
  return k;
}

template <class T>
std::array<long double, 3> relative_velocity(const BodyRecord<T>& a, const BodyRecord<T>& b,
                                             const ContactRecord<T>& c) {
  using L = long double;
  std::array<L, 3> u{};
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const L raj = L(c.c[j]) - L(a.p[j]), rak = L(c.c[k]) - L(a.p[k]);
    const L rbj = L(c.c[j]) - L(b.p[j]), rbk = L(c.c[k]) - L(b.p[k]);
    u[i] = (L(a.v[i]) + (L(a.w[j]) * rak - L(a.w[k]) * raj)) - (L(b.v[i]) + (L(b.w[j]) * rbk - L(b.w[k]) * rbj));
  }
  return u;
}

template <class T>
long double approach_speed(const BodyRecord<T>& a, const BodyRecord<T>& b, const ContactRecord<T>& c) {
  using L = long double;
  const std::array<L, 3> u = relative_velocity(a, b, c);
  return u[0] * L(c.n[0]) + u[1] * L(c.n[1]) + u[2] * L(c.n[2]);
}

template <class T>
void make_approach(const BodyRecord<T>& a, const BodyRecord<T>& b, ContactRecord<T>& c) {
  if (approach_speed(a, b, c) > 0) {
    for (T& x : c.n) x = -x;
  }
}

#define COLLIDE_DRAWS(T)                                                                                           \
  template BodyRecord<T> random_body<T>(SceneRng&, const std::array<double, 3>&);                                  \
  template ContactRecord<T> random_contact<T>(SceneRng&, BodyIndex, BodyIndex, const std::array<double, 3>&, bool, \
                                              double);                                                             \
  template std::array<long double, 3> relative_velocity<T>(const BodyRecord<T>&, const BodyRecord<T>&,             \
                                                           const ContactRecord<T>&);                               \
  template long double approach_speed<T>(const BodyRecord<T>&, const BodyRecord<T>&, const ContactRecord<T>&);     \
  template void make_approach<T>(const BodyRecord<T>&, const BodyRecord<T>&, ContactRecord<T>&);
COLLIDE_DRAWS(float)
COLLIDE_DRAWS(double)
COLLIDE_DRAWS(long double)
#undef COLLIDE_DRAWS

namespace hard {
namespace {

using L = long double;
using V3 = std::array<double, 3>;

V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 scaled(const V3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double norm(const V3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
/// A random unit vector perpendicular to unit d.
V3 perpendicular(SceneRng& rng, const V3& d) {
  for (;;) {
    const V3 t = cross(d, rng.unit_vector());
    const double len = norm(t);
    if (len > 1e-3) return scaled(t, 1 / len);
  }
}
/// 10^x for x uniform in [lo, hi]; every `every`-th draw (k % every == 0) is
/// pinned to `pin`, so the extreme a family promises is always in the scene.
double decade(SceneRng& rng, double lo, double hi, std::size_t k, std::size_t every, double pin) {
  const double x = rng.uniform(lo, hi);
  return std::pow(10.0, k % every == 0 ? pin : x);
}

/// Gives a body the moments and spin of `fit`, keeping its mass.
void shape(BodyRecord<double>& b, Model fit, SceneRng& rng) {
  const double inf = std::numeric_limits<double>::infinity();
  if (fit == Model::particle) {
    b.I[0] = b.I[1] = b.I[2] = inf;
    b.w[0] = b.w[1] = b.w[2] = 0;
  } else if (fit == Model::sphere) {
    const double r = rng.uniform(0.2, 1.5);
    b.I[0] = b.I[1] = b.I[2] = b.m * r * r;
  }
}

/// Largest radius of gyration sqrt(I/m) of a body [m].
double gyration_radius(const BodyRecord<double>& b) { return std::sqrt(std::max({b.I[0], b.I[1], b.I[2]}) / b.m); }

/// One pair as drawn: body a, body b, the contact (indices set when stored).
struct Pair {
  BodyRecord<double> a, b;
  ContactRecord<double> c;
};

/// The support builders' pair (random masses, moments, orientations,
/// velocities; centres 0.1 to 1.5 m from the contact point), shaped for `fit`.
Pair base_pair(SceneRng& rng, Model fit, bool friction) {
  const V3 c = rng.in_box(5);
  auto centre = [&] {
    const V3 d = rng.unit_vector();
    return add(c, scaled(d, -rng.uniform(0.1, 1.5)));
  };
  Pair p;
  p.a = random_body<double>(rng, centre());
  p.b = random_body<double>(rng, centre());
  shape(p.a, fit, rng);
  shape(p.b, fit, rng);
  p.c = random_contact<double>(rng, 0, 1, c, friction);
  return p;
}

/// The drawn double records in the scene's precision (collide/io/scene.hpp).
using detail::narrow;

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
  const BodyRecord<T> a = narrow<T>(p.a), b = narrow<T>(p.b);
  ContactRecord<T> c = narrow<T>(p.c);
  make_approach(a, b, c);
  push_pair(s, a, b, c);
}

/// Pairs drawn by base_pair (friction where `friction(k)`), changed by
/// `modify(rng, k, pair)` and stored approaching: the skeleton most pair
/// families share.
bool odd(std::size_t k) { return k % 2 == 1; }
template <class T, class Modify, class Friction = bool (*)(std::size_t)>
SceneRecords<T> approaching_pairs(std::size_t count, Model fit, std::uint64_t seed, Modify modify,
                                  Friction friction = odd) {
  SceneRng rng(seed);
  SceneRecords<T> s;
  for (std::size_t k = 0; k < count; ++k) {
    Pair p = base_pair(rng, fit, friction(k));
    modify(rng, k, p);
    push_approaching(s, p);
  }
  return s;
}

}  // namespace

// ---------------------------------------------------------------------------
// Pair families.
// ---------------------------------------------------------------------------

template <class T>
SceneRecords<T> mass_ratio_family(std::size_t count, Model fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](SceneRng& rng, std::size_t k, Pair& p) {
    const double ratio = decade(rng, -8, 8, k, 25, (k / 25) % 2 == 0 ? 8 : -8);
    p.b.m *= ratio;
    for (double& i : p.b.I) i *= ratio;
  });
}

Immovable immovable_kind(std::size_t k) { return static_cast<Immovable>(k % 3); }

template <class T>
SceneRecords<T> immovable_family(std::size_t count, Model fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](SceneRng&, std::size_t k, Pair& p) {
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

template <class T>
SceneRecords<T> needle_family(std::size_t count, std::uint64_t seed) {
  return approaching_pairs<T>(count, Model::rigid, seed, [](SceneRng& rng, std::size_t k, Pair& p) {
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

template <class T>
SceneRecords<T> long_lever_family(std::size_t count, Model fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](SceneRng& rng, std::size_t k, Pair& p) {
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

template <class T>
SceneRecords<T> grazing_family(std::size_t count, Model fit, std::uint64_t seed) {
  SceneRng rng(seed);
  SceneRecords<T> s;
  for (std::size_t k = 0; k < count; ++k) {
    const Pair p = base_pair(rng, fit, k % 2 == 1);
    BodyRecord<T> a = narrow<T>(p.a);
    const BodyRecord<T> b = narrow<T>(p.b);
    ContactRecord<T> c = narrow<T>(p.c);
    const double ratio = decade(rng, -7, 0, k, 25, -7);
    const V3 n{double(c.n[0]), double(c.n[1]), double(c.n[2])};
    const V3 t = perpendicular(rng, n);
    const double speed = rng.uniform(1, 5);
    const std::array<L, 3> u = relative_velocity(a, b, c);
    for (int i = 0; i < 3; ++i) {
      const L target = L(speed) * (L(t[i]) - L(ratio) * L(n[i]));
      a.v[i] = static_cast<T>(L(a.v[i]) + (target - u[i]));
    }
    make_approach(a, b, c);
    push_pair(s, a, b, c);
  }
  return s;
}

template <class T>
SceneRecords<T> unit_scale_family(std::size_t count, Model fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](SceneRng& rng, std::size_t k, Pair& p) {
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

template <class T>
SceneRecords<T> subnormal_family(std::size_t count, Model fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [fit](SceneRng& rng, std::size_t, Pair& p) {
    for (BodyRecord<double>* b : {&p.a, &p.b}) {
      for (int i = 0; i < 3; ++i) {
        const double sign = rng.chance(0.5) ? 1 : -1;
        b->v[i] = sign * std::pow(10.0, rng.uniform(-45.5, -38));
        if (fit != Model::particle) b->w[i] = -sign * std::pow(10.0, rng.uniform(-45.5, -38));
      }
    }
  });
}

template <class T>
SceneRecords<T> separating_resting_family(std::size_t count, Model fit, std::uint64_t seed) {
  SceneRng rng(seed);
  SceneRecords<T> s;
  for (std::size_t k = 0; k < count; ++k) {
    Pair p = base_pair(rng, fit, (k / 2) % 2 == 0);
    if (k % 2 == 0) {
      for (;;) {
        BodyRecord<T> a = narrow<T>(p.a), b = narrow<T>(p.b);
        ContactRecord<T> c = narrow<T>(p.c);
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
    BodyRecord<T> a = narrow<T>(p.a), b = narrow<T>(p.b);
    ContactRecord<T> c = narrow<T>(p.c);
    b.v[axis] = a.v[axis];
    for (BodyRecord<T>* body : {&a, &b}) {
      // Either w parallel to n (particles have no spin at all) or r parallel
      // to n, for all the body's components at once.
      const bool spin_along_n = fit == Model::particle || rng.chance(0.5);
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

template <class T>
SceneRecords<T> restitution_family(std::size_t count, Model fit, std::uint64_t seed) {
  return approaching_pairs<T>(
      count, fit, seed, [](SceneRng&, std::size_t k, Pair& p) { p.c.e = static_cast<double>(k % 2); },
      [](std::size_t k) { return k % 4 >= 2; });
}

template <class T>
SceneRecords<T> stick_slip_family(std::size_t count, Model fit, std::uint64_t seed) {
  // mu = 1e6 sticks: the reference then reports the sticking impulse as jt.
  SceneRecords<T> s = approaching_pairs<T>(
      count, fit, seed, [](SceneRng&, std::size_t, Pair& p) { p.c.mu = 1e6; }, [](std::size_t) { return true; });
  SceneRng rng(seed + 1);
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

template <class T>
SceneRecords<T> spin_family(std::size_t count, Model fit, std::uint64_t seed) {
  return approaching_pairs<T>(count, fit, seed, [](SceneRng& rng, std::size_t, Pair& p) {
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

// ---------------------------------------------------------------------------
// The catalogue.
// ---------------------------------------------------------------------------

std::vector<HardScene> hard_scene_catalogue() {
  const Model all[] = {Model::particle, Model::sphere, Model::rigid};
  std::vector<HardScene> c;
  auto pairs = [&](const char* family, std::initializer_list<Model> fits, bool float_only = false) {
    for (const Model fit : fits) c.push_back({family, fit, false, float_only});
  };
  pairs("mass-ratio", {all[0], all[1], all[2]});
  pairs("immovable", {all[0], all[1], all[2]});
  pairs("needle", {Model::rigid});
  pairs("long-lever", {Model::sphere, Model::rigid});
  pairs("grazing", {all[0], all[1], all[2]});
  pairs("unit-scales", {all[0], all[1], all[2]});
  pairs("subnormal", {all[0], all[1], all[2]}, true);
  pairs("separating-resting", {all[0], all[1], all[2]});
  pairs("e-0-and-1", {all[0], all[1], all[2]});
  pairs("stick-slip", {all[0], all[1], all[2]});
  pairs("spin-dominated", {Model::sphere, Model::rigid});
  for (const char* family : {"cradle", "cradle-mixed"}) {
    c.push_back({family, Model::particle, true, false});  // along an axis
    c.push_back({family, Model::sphere, true, false});    // along a random axis
  }
  for (const char* family : {"star", "star-fixed-hub", "cluster"}) {
    for (const Model fit : all) c.push_back({family, fit, true, false});
  }
  return c;
}

template <class T>
SceneRecords<T> off_unit_directions(SceneRecords<T> records, std::uint64_t seed) {
  SceneRng rng(seed);
  for (ContactRecord<T>& c : records.contacts) {
    const double scale = 1 + rng.uniform(-9e-4, 9e-4);
    for (T& x : c.n) x = static_cast<T>(static_cast<double>(x) * scale);
  }
  for (BodyRecord<T>& b : records.bodies) {
    const double scale = rng.log_uniform(0.5, 2.0);
    for (T& x : b.q) x = static_cast<T>(static_cast<double>(x) * scale);
  }
  return records;
}

template <class T>
Scene<T> build_hard_scene(const HardScene& scene, std::size_t count) {
  // The seeds of tests/hard/, so that the report shows the scenes the tests hold.
  const std::string& f = scene.family;
  const Model fit = scene.fit;
  if (f == "mass-ratio") return mass_ratio_family<T>(count, fit, 11).scene();
  if (f == "immovable") return immovable_family<T>(count, fit, 12).scene();
  if (f == "needle") return needle_family<T>(count, 13).scene();
  if (f == "long-lever") return long_lever_family<T>(count, fit, 14).scene();
  if (f == "grazing") return grazing_family<T>(count, fit, 15).scene();
  if (f == "unit-scales") return unit_scale_family<T>(count, fit, 16).scene();
  if (f == "subnormal") return subnormal_family<T>(count, fit, 17).scene();
  if (f == "separating-resting") return separating_resting_family<T>(count, fit, 18).scene();
  if (f == "e-0-and-1") return restitution_family<T>(count, fit, 19).scene();
  if (f == "stick-slip") return stick_slip_family<T>(count, fit, 20).scene();
  if (f == "spin-dominated") return spin_family<T>(count, fit, 21).scene();
  if (f == "cradle" || f == "cradle-mixed") {
    // Axis-aligned for particles; otherwise test_hard_shared's random axis.
    V3 axis = {1, 0, 0};
    if (fit != Model::particle) axis = SceneRng(31).unit_vector();
    const bool classic = f == "cradle";
    return cradle_scene<T>(20, axis, classic, classic, false, classic ? 32 : 33).scene();
  }
  if (f == "star" || f == "star-fixed-hub") return star_scene<T>(1000, f == "star-fixed-hub", fit, 34).scene();
  if (f == "cluster") return cluster_scene<T>(80, 1.0, fit, 35).scene();
  throw std::invalid_argument("unknown hard family '" + f + "'");
}

#define COLLIDE_FAMILIES(T)                                                                             \
  template SceneRecords<T> mass_ratio_family<T>(std::size_t, Model, std::uint64_t);                     \
  template SceneRecords<T> immovable_family<T>(std::size_t, Model, std::uint64_t);                      \
  template SceneRecords<T> needle_family<T>(std::size_t, std::uint64_t);                                \
  template SceneRecords<T> long_lever_family<T>(std::size_t, Model, std::uint64_t);                     \
  template SceneRecords<T> grazing_family<T>(std::size_t, Model, std::uint64_t);                        \
  template SceneRecords<T> unit_scale_family<T>(std::size_t, Model, std::uint64_t);                     \
  template SceneRecords<T> subnormal_family<T>(std::size_t, Model, std::uint64_t);                      \
  template SceneRecords<T> separating_resting_family<T>(std::size_t, Model, std::uint64_t);             \
  template SceneRecords<T> restitution_family<T>(std::size_t, Model, std::uint64_t);                    \
  template SceneRecords<T> stick_slip_family<T>(std::size_t, Model, std::uint64_t);                     \
  template SceneRecords<T> spin_family<T>(std::size_t, Model, std::uint64_t);                           \
  template SceneRecords<T> cradle_scene<T>(std::size_t, const std::array<double, 3>&, bool, bool, bool, \
                                           std::uint64_t);                                              \
  template SceneRecords<T> star_scene<T>(std::size_t, bool, Model, std::uint64_t);                      \
  template SceneRecords<T> cluster_scene<T>(std::size_t, double, Model, std::uint64_t);                 \
  template SceneRecords<T> off_unit_directions<T>(SceneRecords<T>, std::uint64_t);                      \
  template Scene<T> build_hard_scene<T>(const HardScene&, std::size_t);
COLLIDE_FAMILIES(float)
COLLIDE_FAMILIES(double)
#undef COLLIDE_FAMILIES

}  // namespace hard
}  // namespace collide
