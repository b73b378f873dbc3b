// hard_scenes/draws.cpp - the draws the hard-case scenes are made of: SceneRng
// and the body and contact builders of collide/eval/hard_scenes.hpp, and the
// draws the families share (hard_scenes/draws.hpp).
//
// Design notes
// ------------
// * Apart from the families, so that a family file holds only what makes its
//   scenes hard, and every family draws its bodies, contacts and directions
//   through the same code: a scene is a function of its seed through these
//   draws alone.
#include "hard_scenes/draws.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace collide {

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

namespace hard_detail {

V3 perpendicular(SceneRng& rng, const V3& d) {
  for (;;) {
    const V3 t = cross(d, rng.unit_vector());
    const double len = norm(t);
    if (len > 1e-3) return scaled(t, 1 / len);
  }
}
double decade(SceneRng& rng, double lo, double hi, std::size_t k, std::size_t every, double pin) {
  const double x = rng.uniform(lo, hi);
  return std::pow(10.0, k % every == 0 ? pin : x);
}

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

double gyration_radius(const BodyRecord<double>& b) { return std::sqrt(std::max({b.I[0], b.I[1], b.I[2]}) / b.m); }

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

}  // namespace hard_detail
}  // namespace collide
