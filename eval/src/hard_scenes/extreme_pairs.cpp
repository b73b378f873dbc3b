// hard_scenes/extreme_pairs.cpp - the pair families of values at the ends of
// their ranges (collide/eval/hard_scenes.hpp): mass ratios, immovable
// bodies, needles, long levers, unit scales, subnormal speeds and
// spin-dominated contacts.
//
// Design notes
// ------------
// * Grouped by what they stress: each of these takes one magnitude of an
//   ordinary pair (a mass, a moment, a lever arm, a scale, a speed) towards
//   an end of what the law's arithmetic holds, where a formula that is
//   exact on paper loses digits, underflows or overflows. The pairs on the boundaries
//   between the law's cases are in boundary_pairs.cpp.
// * Every family is an approaching_pairs skeleton (hard_scenes/draws.hpp)
//   and a change of the drawn pair, so that the scenes differ from the
//   ordinary pairs only in what the family promises.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "hard_scenes/draws.hpp"

namespace collide::hard {
namespace {

using hard_detail::add;
using hard_detail::approaching_pairs;
using hard_detail::decade;
using hard_detail::gyration_radius;
using hard_detail::norm;
using hard_detail::Pair;
using hard_detail::perpendicular;
using hard_detail::scaled;
using hard_detail::V3;

}  // namespace

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

COLLIDE_PAIR_FAMILY(mass_ratio_family)
COLLIDE_PAIR_FAMILY(immovable_family)
COLLIDE_PAIR_FAMILY(long_lever_family)
COLLIDE_PAIR_FAMILY(unit_scale_family)
COLLIDE_PAIR_FAMILY(subnormal_family)
COLLIDE_PAIR_FAMILY(spin_family)
template SceneRecords<float> needle_family<float>(std::size_t, std::uint64_t);
template SceneRecords<double> needle_family<double>(std::size_t, std::uint64_t);

}  // namespace collide::hard
