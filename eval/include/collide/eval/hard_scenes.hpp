// collide/eval/hard_scenes.hpp - the hard-case scene families: scenes
// built to stress one numerical weakness each, as pure functions of (count,
// body model to fit, seed). The tests (tests/hard/), the fixture generator,
// `collide report --hard` and the attribution tool all draw them from here.
//
// Design notes
// ------------
// * Every family is drawn in double with SceneRng (std::mt19937_64 and
//   libstdc++'s distributions, fixed for a seed) and the body and contact
//   builders below, then stored in T (float or double) through
//   BodyRecord<T>: the scene a kernel sees is the rounded one, and anything a
//   family promises (approaching, exactly resting, a mass ratio reached) is
//   established on the stored T values, evaluated in long double.
// * Each body is shaped for one body model (collide/model.hpp), the family's
//   `fit`: Model::particle - infinite moments and w = 0 (particle, sphere
//   and rigid fit); Model::sphere - three equal moments (sphere and rigid
//   fit); Model::rigid - anisotropic moments, random orientation (rigid
//   only). choose_model() of a scene shaped for `fit` says `fit`.
// * Pair families put pair k on bodies 2k and 2k+1; every other pair has a
//   and b swapped, so that the SIMD path runs both its paired-load and its
//   gather layout on the hard values.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/scene.hpp"
#include "collide/model.hpp"

namespace collide {

// ---------------------------------------------------------------------------
// The draws the scenes are made of.
// ---------------------------------------------------------------------------

/// Deterministic random draws for scene builders: std::mt19937_64 from a
/// seed, through libstdc++'s distributions (fixed for a seed), so a scene can
/// always be rebuilt from the seed printed with it.
class SceneRng {
 public:
  explicit SceneRng(std::uint64_t seed) : g_(seed) {}

  double uniform(double lo, double hi);
  double log_uniform(double lo, double hi);  ///< exp of uniform in [log lo, log hi)
  std::size_t index(std::size_t n);          ///< uniform in [0, n)
  bool chance(double p);                     ///< true with probability p
  double normal();                           ///< standard normal
  std::array<double, 3> unit_vector();
  std::array<double, 4> quaternion();  ///< a uniformly distributed rotation (unit)
  std::array<double, 3> in_box(double half);

 private:
  std::mt19937_64 g_;
};

/// A scene as records, before it is pushed into buffers: builders (and tests
/// that splice a scene, insert a pair, poison a value) edit the records, so
/// that every value goes through push_back exactly once.
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

/// A random movable body at p: mass log-uniform in [0.1, 10] kg, principal
/// moments m r_i^2 with radii of gyration in [0.2, 1.5] m (anisotropy up to
/// ~56), a uniform random orientation, |v_i|, |w_i| <= 5.
template <class T>
BodyRecord<T> random_body(SceneRng& rng, const std::array<double, 3>& p);

/// A contact of bodies ia and ib at c with a random unit normal; e uniform in
/// [0, 1] when `e` < 0, else `e`; mu uniform in [0, 1] with `friction`, else 0.
template <class T>
ContactRecord<T> random_contact(SceneRng& rng, BodyIndex ia, BodyIndex ib, const std::array<double, 3>& c,
                                bool friction, double e = -1);

/// The velocity of a's contact point relative to b's, (va + wa x ra) -
/// (vb + wb x rb), in long double from the stored (T) values.
template <class T>
std::array<long double, 3> relative_velocity(const BodyRecord<T>& a, const BodyRecord<T>& b, const ContactRecord<T>& c);

/// u . n of a contact, in long double from the stored (T) values: the sign
/// the builders use to make a contact approach.
template <class T>
long double approach_speed(const BodyRecord<T>& a, const BodyRecord<T>& b, const ContactRecord<T>& c);

/// Flips n when the contact separates, so that it approaches.
template <class T>
void make_approach(const BodyRecord<T>& a, const BodyRecord<T>& b, ContactRecord<T>& c);

// ---------------------------------------------------------------------------
// The families.
// ---------------------------------------------------------------------------

namespace hard {

/// Pair families. Each returns `count` independent pairs shaped for `fit`.

/// Mass ratios m_b / m_a = 10^x, x uniform in [-8, 8] (every 25th pinned to
/// +-8); b's moments scale with its mass.
template <class T>
SceneRecords<T> mass_ratio_family(std::size_t count, Model fit, std::uint64_t seed);

/// Which side of an immovable-family pair is immovable: pair k has kind k % 3.
enum class Immovable { a, b, both };
Immovable immovable_kind(std::size_t k);

/// An immovable body (m = inf) on side a, side b or both. Its moments are
/// finite or inf (alternately); it moves kinematically (v, and w unless the
/// scene is for particles).
template <class T>
SceneRecords<T> immovable_family(std::size_t count, Model fit, std::uint64_t seed);

/// Needle-thin body a (rigid only): moments I_y = I_z = m L^2 / 3 of a rod of
/// half-length L, I_x = I_y * 10^x with x in [-12, -3] (every 25th pinned to
/// -12), random orientation, struck at a tip: c = p + R (+-L, 0, 0). Body b is
/// an ordinary rigid body, immovable in every fourth pair.
template <class T>
SceneRecords<T> needle_family(std::size_t count, std::uint64_t seed);

/// Long levers (sphere or rigid): the contact point |r| = rho * 10^x from
/// a's centre, x in [0, 4] (every 25th pinned to 4), rho a's largest radius
/// of gyration. In every fourth pair the normal is within 10^-6..10^-1 rad
/// of r, so that r x n is small and cancels, and neither body spins.
template <class T>
SceneRecords<T> long_lever_family(std::size_t count, Model fit, std::uint64_t seed);

/// Grazing approach: the relative velocity is set (through v_a) so that
/// vn / |u| = -10^x, x in [-7, 0] (every 25th pinned to -7), in long double
/// from the stored values; the rounding of v_a to T then moves the ratio by
/// up to eps(T) |v_a| / |u|. Half of the pairs have friction.
template <class T>
SceneRecords<T> grazing_family(std::size_t count, Model fit, std::uint64_t seed);

/// Unit scales: length, mass and speed scales 10^x each, x in [-5, 5]
/// independently (every 25th pair at a corner of the cube):
/// m *= M, I *= M L^2, p, c *= L, v *= V, w *= V / L.
template <class T>
SceneRecords<T> unit_scale_family(std::size_t count, Model fit, std::uint64_t seed);

/// Subnormal speeds (meant for float): every component of v and w is
/// +-10^x, x in [-45.5, -38] (float's subnormals are 1.4e-45 .. 1.2e-38);
/// masses, moments and lengths are ordinary.
template <class T>
SceneRecords<T> subnormal_family(std::size_t count, Model fit, std::uint64_t seed);

/// Exactly separating (even k: vn > 0.01 S, far from any rounding) and
/// exactly resting (odd k: vn == 0 in every precision) contacts. A resting
/// contact has an axis normal +-e_i, equal v_i on both bodies, and each
/// body's w either parallel to n or its lever arm r parallel to n, with the
/// other components exactly 0, so that every product in (w x r) . n is an
/// exact zero in T and in long double alike.
template <class T>
SceneRecords<T> separating_resting_family(std::size_t count, Model fit, std::uint64_t seed);

/// Restitution at its ends: e = 0 and e = 1, each with and without friction
/// (pair k: e = k % 2, friction when k % 4 >= 2).
template <class T>
SceneRecords<T> restitution_family(std::size_t count, Model fit, std::uint64_t seed);

/// Friction at the stick/slip boundary: mu is set so that mu jn equals the
/// sticking impulse |ut| / K(t) of the long double reference, times
/// (1 + d) with d = 0 (every fifth pair) or +-10^x, x in [-8, -1]: the
/// contacts sit on both sides of the min() in jt = min(|ut|/K(t), mu jn).
template <class T>
SceneRecords<T> stick_slip_family(std::size_t count, Model fit, std::uint64_t seed);

/// Spin-dominated contacts (sphere or rigid): |w| = 10^x rad/s, x in [1, 4],
/// and each body's |v| = 10^y |w| |r|, y in [-6, -2]: the relative velocity
/// is almost all w x r.
template <class T>
SceneRecords<T> spin_family(std::size_t count, Model fit, std::uint64_t seed);

/// The scene as a caller might hand it over, rather than as the builders
/// above store it: every normal scaled by 1 + d, d uniform in
/// [-9e-4, 9e-4] (inside the input tolerance of 1e-3, collide/rules.hpp),
/// and every quaternion by a factor log-uniform in [1/2, 2], each value
/// rounded once to T. The law normalises n and q, so the physics is the
/// same; what changes is what the kernels read, and an evaluation that
/// rounds n or q before the law does is off by the rounding.
template <class T>
SceneRecords<T> off_unit_directions(SceneRecords<T> records, std::uint64_t seed);

/// Shared-body scenes.

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
SceneRecords<T> cradle_scene(std::size_t longest, const std::array<double, 3>& axis, bool elastic, bool equal_masses,
                             bool reversed, std::uint64_t seed);

/// A star: body 0, the hub, in `spokes` contacts, one with each satellite
/// (bodies 1 .. spokes), which sit around it in random directions and fly
/// at it. Contact k joins satellite k+1 (a) and the hub (b), n from the hub
/// towards the satellite. The hub is immovable when `fixed_hub`, otherwise
/// 10 times as heavy as a satellite on average. e uniform in [0, 1];
/// friction in half of the contacts.
template <class T>
SceneRecords<T> star_scene(std::size_t spokes, bool fixed_hub, Model fit, std::uint64_t seed);

/// A dense cluster: `count` bodies in a 2 m box, a contact for every pair
/// closer than `reach` (at the midpoint, n along the line of centres, from b
/// towards a), listed in random order. Velocities random, so some contacts
/// approach and some separate, and a body is in many contacts. e uniform in
/// [0, 1], friction in half of the contacts. No immovable body, so momentum
/// is conserved.
template <class T>
SceneRecords<T> cluster_scene(std::size_t count, double reach, Model fit, std::uint64_t seed);

/// One hard scene of the catalogue below: a family at its canonical seed
/// (the one tests/hard/ uses), shaped for one model.
struct HardScene {
  std::string family;  ///< "mass-ratio", "cradle-mixed", ... (hard_scene_catalogue)
  Model fit;           ///< the model the scene is shaped for, the cheapest that fits it
  bool shared;         ///< contacts share bodies (a chain): cradles, stars, the cluster
  bool float_only;     ///< meant for float only (subnormal speeds)
};

/// Every family of this header at every model it can be shaped for, in a
/// fixed order: the pair families, then the cradles (axis-aligned: particle;
/// along a random axis: sphere; equal masses and e = 1, then mixed), the
/// star with a movable and with an immovable hub, and the cluster.
std::vector<HardScene> hard_scene_catalogue();

/// Builds a catalogue scene in T: pair families with `count` pairs, the
/// shared scenes at their fixed sizes (cradles of 2 .. 20 spheres, 190
/// contacts; stars of 1000 spokes; a cluster of 80 bodies, about 870
/// contacts). Throws std::invalid_argument for an unknown family.
template <class T>
Scene<T> build_hard_scene(const HardScene& scene, std::size_t count);

}  // namespace hard
}  // namespace collide
