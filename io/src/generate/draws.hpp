// generate/draws.hpp - the draws the random scenes share (private to the
// library): the counter-based generator, its streams, a few vector
// operations and the body and contact pieces of more than one scene kind
// (collide/io/generate.hpp).
//
// Design notes
// ------------
// * Counter-based randomness: every pair, debris body and debris contact owns
//   a stream keyed by (seed, scene kind, index) whose n-th draw is
//   splitmix64(key + n * golden). No state is shared between items, so item k
//   is a pure function of (seed, k): chunked, parallel and streaming
//   generation all produce the same scene, bit for bit.
// * Every stream's salt is listed here, in one place, so that no two scenes
//   or item kinds can come to share a key.
// * Draws follow the source page's test program (masses, principal moments,
//   a rotation vector for the orientation, velocities, contact offsets, a
//   random unit normal, re-drawn until the bodies approach), with ranges made
//   symmetric and kept away from zero so that every value is a sane physical
//   input: m, I in [0.1, 20), v, w components in [-10, 10).
// * "Approaching" is required with a margin (u.n < -kMinApproachSpeed), so
//   that rounding the scene to float cannot turn an approaching pair into a
//   separating one.
// * mu is always drawn and zeroed without friction, so a scene with and one
//   without friction share every other value.
// * Only sin, cos and sqrt of libm are used; a scene is reproducible on the
//   same platform (libm's sin/cos are not guaranteed identical elsewhere).
// * Inline, in a namespace of their own: every item of every scene goes
//   through these few lines, and the library is compiled in unity batches
//   too, where one definition serves every file of a batch.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/model.hpp"

namespace collide::generate_detail {

inline constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ULL;
// Stream salts: distinct scenes and item kinds never share a key.
inline constexpr std::uint64_t kPairStream = 0x7061697273000001ULL;
inline constexpr std::uint64_t kDebrisBodyStream = 0x6465627269730002ULL;
inline constexpr std::uint64_t kDebrisContactStream = 0x6465627269730003ULL;
inline constexpr std::uint64_t kPileBodyStream = 0x70696c6500000004ULL;
inline constexpr std::uint64_t kPileContactStream = 0x70696c6500000005ULL;
inline constexpr std::uint64_t kPileShuffleStream = 0x70696c6500000006ULL;
inline constexpr std::uint64_t kChainBodyStream = 0x636861696e000007ULL;
inline constexpr std::uint64_t kChainContactStream = 0x636861696e000008ULL;

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kMinApproachSpeed = 1e-2;  // [m/s]

inline std::uint64_t splitmix64(std::uint64_t z) {
  z += kGolden;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// The draws of one item: a pure function of (seed, stream, index, draw #).
class CounterRng {
 public:
  CounterRng(std::uint64_t seed, std::uint64_t stream, std::uint64_t index)
      : key_(splitmix64(splitmix64(seed ^ stream) + index)) {}
  std::uint64_t next() { return splitmix64(key_ + kGolden * ++counter_); }
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n), n > 0 (modulo bias below 2^-40 for n < 2^24).
  std::uint64_t below(std::uint64_t n) { return next() % n; }

 private:
  std::uint64_t key_;
  std::uint64_t counter_ = 0;
};

struct Vec3 {
  double x, y, z;
};
inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline Vec3 to_vec(const double* v) { return {v[0], v[1], v[2]}; }
inline void store(Vec3 v, double* out) {
  out[0] = v.x;
  out[1] = v.y;
  out[2] = v.z;
}

inline Vec3 uniform_vec(CounterRng& rng, double lo, double hi) {
  const double x = rng.uniform(lo, hi);
  const double y = rng.uniform(lo, hi);
  const double z = rng.uniform(lo, hi);
  return {x, y, z};
}

/// A unit vector uniform on the sphere (Archimedes: z uniform in [-1, 1]).
inline Vec3 unit_vec(CounterRng& rng) {
  const double z = rng.uniform(-1.0, 1.0);
  const double phi = rng.uniform(0.0, 2.0 * kPi);
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

/// The unit quaternion (w, x, y, z) of a rotation vector (angle = |rv|).
inline void store_rotation(Vec3 rv, double* q) {
  const double angle = std::sqrt(dot(rv, rv));
  if (angle > 1e-12) {
    const double s = std::sin(0.5 * angle) / angle;
    q[0] = std::cos(0.5 * angle);
    q[1] = rv.x * s;
    q[2] = rv.y * s;
    q[3] = rv.z * s;
  } else {
    q[0] = 1.0;
    q[1] = q[2] = q[3] = 0.0;
  }
}

/// A random movable body: the page's draws, in sane positive ranges.
/// `half_extent` is the half size of the box the centre lies in.
inline void draw_movable_body(CounterRng& rng, double half_extent, BodyRecord<double>& body) {
  body.m = rng.uniform(0.1, 20.0);
  for (double& i : body.I) i = rng.uniform(0.1, 20.0);
  // Orientation from a rotation vector, angle = |vector|, as the page does.
  store_rotation(uniform_vec(rng, -kPi, kPi), body.q);
  store(uniform_vec(rng, -half_extent, half_extent), body.p);
  store(uniform_vec(rng, -10.0, 10.0), body.v);
  store(uniform_vec(rng, -10.0, 10.0), body.w);
}

/// Makes a drawn body fit a smaller model (model.hpp), after all of its
/// draws, so that the scenes of every model share positions, masses and
/// velocities: a particle cannot rotate and does not spin, a sphere has one
/// moment.
inline void fit_model(Model model, BodyRecord<double>& body) {
  if (model == Model::particle) {
    body.I[0] = body.I[1] = body.I[2] = std::numeric_limits<double>::infinity();
    body.w[0] = body.w[1] = body.w[2] = 0.0;
  } else if (model == Model::sphere) {
    body.I[1] = body.I[2] = body.I[0];
  }
}

/// u . n for a contact at c, u = (va + wa x ra) - (vb + wb x rb).
inline double approach_speed(const BodyRecord<double>& a, const BodyRecord<double>& b, Vec3 c, Vec3 n) {
  const Vec3 ra = c - to_vec(a.p);
  const Vec3 rb = c - to_vec(b.p);
  const Vec3 u = (to_vec(a.v) + cross(to_vec(a.w), ra)) - (to_vec(b.v) + cross(to_vec(b.w), rb));
  return dot(u, n);
}

/// The immovable ground: infinite mass and moments, at rest at p.
inline void store_ground(Vec3 p, BodyRecord<double>& body) {
  const double inf = std::numeric_limits<double>::infinity();
  body = BodyRecord<double>{};
  body.m = inf;
  body.I[0] = body.I[1] = body.I[2] = inf;
  store(p, body.p);
}

}  // namespace collide::generate_detail
