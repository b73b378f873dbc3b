// hard_scenes/boundary_pairs.cpp - the pair families on the boundaries between
// the law's cases (collide/eval/hard_scenes.hpp): grazing approach, exactly
// separating and exactly resting contacts, restitution at 0 and 1, and
// friction at the stick/slip boundary.
//
// Design notes
// ------------
// * Grouped by what they stress: the law takes another path by the sign of
//   the normal speed (an impulse or none) and by the min() of friction
//   (sticking or sliding), and its restitution ends at e = 0 and e = 1; a
//   contact that a rounding puts on the wrong side of a path gets another
//   impulse altogether, not one an ulp off. These families put contacts on
//   or next to each such edge; the extremes of single values are in
//   extreme_pairs.cpp.
// * A promise about a boundary is kept on the stored values, evaluated in
//   long double (relative_velocity), so that rounding the scene to float
//   cannot move a contact across it.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "collide/eval/reference.hpp"
#include "hard_scenes/draws.hpp"

namespace collide::hard {
namespace {

using L = long double;
using detail::narrow;
using hard_detail::approaching_pairs;
using hard_detail::base_pair;
using hard_detail::decade;
using hard_detail::Pair;
using hard_detail::perpendicular;
using hard_detail::push_pair;
using hard_detail::V3;

}  // namespace

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

COLLIDE_PAIR_FAMILY(grazing_family)
COLLIDE_PAIR_FAMILY(separating_resting_family)
COLLIDE_PAIR_FAMILY(restitution_family)
COLLIDE_PAIR_FAMILY(stick_slip_family)

}  // namespace collide::hard
