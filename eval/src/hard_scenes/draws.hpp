// hard_scenes/draws.hpp - the pieces the hard-case families are drawn from
// (private to the library): a few vector operations on double triples, the
// draws every family shares (draws.cpp) and the skeleton of the pair
// families.
//
// Design notes
// ------------
// * One place for what several family files use, so that a family reads as
//   what makes it hard and nothing else: the pair families (extreme_pairs.cpp,
//   boundary_pairs.cpp) change a base_pair and store it, the shared-body
//   scenes (shared_bodies.cpp) shape their bodies and place them with the
//   same vector operations.
// * Everything is drawn in double and stored in T once, through
//   detail::narrow (collide/io/scene.hpp), so that what a family promises is
//   established on the stored values (collide/eval/hard_scenes.hpp).
// * A namespace of its own rather than each file's anonymous one: the
//   library is compiled in unity batches too, and one definition serves
//   every file of a batch.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "collide/eval/hard_scenes.hpp"

namespace collide::hard_detail {

using V3 = std::array<double, 3>;

inline V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline V3 scaled(const V3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double norm(const V3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// A random unit vector perpendicular to unit d.
V3 perpendicular(SceneRng& rng, const V3& d);

/// 10^x for x uniform in [lo, hi]; every `every`-th draw (k % every == 0) is
/// pinned to `pin`, so the extreme a family promises is always in the scene.
double decade(SceneRng& rng, double lo, double hi, std::size_t k, std::size_t every, double pin);

/// Gives a body the moments and spin of `fit`, keeping its mass.
void shape(BodyRecord<double>& b, Model fit, SceneRng& rng);

/// Largest radius of gyration sqrt(I/m) of a body [m].
double gyration_radius(const BodyRecord<double>& b);

/// One pair as drawn: body a, body b, the contact (indices set when stored).
struct Pair {
  BodyRecord<double> a, b;
  ContactRecord<double> c;
};

/// The support builders' pair (random masses, moments, orientations,
/// velocities; centres 0.1 to 1.5 m from the contact point), shaped for `fit`.
Pair base_pair(SceneRng& rng, Model fit, bool friction);

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
  const BodyRecord<T> a = detail::narrow<T>(p.a), b = detail::narrow<T>(p.b);
  ContactRecord<T> c = detail::narrow<T>(p.c);
  make_approach(a, b, c);
  push_pair(s, a, b, c);
}

/// Pairs drawn by base_pair (friction where `friction(k)`), changed by
/// `modify(rng, k, pair)` and stored approaching: the skeleton most pair
/// families share.
inline bool odd(std::size_t k) { return k % 2 == 1; }
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

}  // namespace collide::hard_detail

/// Instantiates the pair family `name` (count, fit, seed) in namespace
/// collide::hard for both scene precisions: every pair family but the
/// needle (rigid only) has that signature.
// NOLINTBEGIN(bugprone-macro-parentheses): `name` is a template's name, which takes no parentheses
#define COLLIDE_PAIR_FAMILY(name)                                              \
  template SceneRecords<float> name<float>(std::size_t, Model, std::uint64_t); \
  template SceneRecords<double> name<double>(std::size_t, Model, std::uint64_t);
// NOLINTEND(bugprone-macro-parentheses)
