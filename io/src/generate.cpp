// generate.cpp - the random "pairs" and "debris" scenes.
//
// Design notes
// ------------
// * Counter-based randomness: every pair, debris body and debris contact owns
//   a stream keyed by (seed, scene kind, index) whose n-th draw is
//   splitmix64(key + n * golden). No state is shared between items, so item k
//   is a pure function of (seed, k): chunked, parallel and streaming
//   generation all produce the same scene, bit for bit.
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
#include "collide/io/generate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>


namespace collide {
namespace {

constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ULL;
// Stream salts: distinct scenes and item kinds never share a key.
constexpr std::uint64_t kPairStream = 0x7061697273000001ULL;
constexpr std::uint64_t kDebrisBodyStream = 0x6465627269730002ULL;
constexpr std::uint64_t kDebrisContactStream = 0x6465627269730003ULL;

constexpr double kPi = 3.14159265358979323846;
constexpr double kMinApproachSpeed = 1e-2;  // [m/s]

std::uint64_t splitmix64(std::uint64_t z) {
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
Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
Vec3 to_vec(const double* v) { return {v[0], v[1], v[2]}; }
void store(Vec3 v, double* out) {
  out[0] = v.x;
  out[1] = v.y;
  out[2] = v.z;
}

Vec3 uniform_vec(CounterRng& rng, double lo, double hi) {
  const double x = rng.uniform(lo, hi);
  const double y = rng.uniform(lo, hi);
  const double z = rng.uniform(lo, hi);
  return {x, y, z};
}

/// A unit vector uniform on the sphere (Archimedes: z uniform in [-1, 1]).
Vec3 unit_vec(CounterRng& rng) {
  const double z = rng.uniform(-1.0, 1.0);
  const double phi = rng.uniform(0.0, 2.0 * kPi);
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

/// A random movable body: the page's draws, in sane positive ranges.
/// `half_extent` is the half size of the box the centre lies in.
void draw_movable_body(CounterRng& rng, double half_extent, BodyRecord<double>& body) {
  body.m = rng.uniform(0.1, 20.0);
  for (double& i : body.I) i = rng.uniform(0.1, 20.0);
  // Orientation from a rotation vector, angle = |vector|, as the page does.
  const Vec3 rv = uniform_vec(rng, -kPi, kPi);
  const double angle = std::sqrt(dot(rv, rv));
  if (angle > 1e-12) {
    const double s = std::sin(0.5 * angle) / angle;
    body.q[0] = std::cos(0.5 * angle);
    body.q[1] = rv.x * s;
    body.q[2] = rv.y * s;
    body.q[3] = rv.z * s;
  } else {
    body.q[0] = 1.0;
    body.q[1] = body.q[2] = body.q[3] = 0.0;
  }
  store(uniform_vec(rng, -half_extent, half_extent), body.p);
  store(uniform_vec(rng, -10.0, 10.0), body.v);
  store(uniform_vec(rng, -10.0, 10.0), body.w);
}

/// Makes a drawn body fit a smaller model (model.hpp), after all of its
/// draws, so that the scenes of every model share positions, masses and
/// velocities: a particle cannot rotate and does not spin, a sphere has one
/// moment.
void fit_model(Model model, BodyRecord<double>& body) {
  if (model == Model::particle) {
    body.I[0] = body.I[1] = body.I[2] = std::numeric_limits<double>::infinity();
    body.w[0] = body.w[1] = body.w[2] = 0.0;
  } else if (model == Model::sphere) {
    body.I[1] = body.I[2] = body.I[0];
  }
}

/// u . n for a contact at c, u = (va + wa x ra) - (vb + wb x rb).
double approach_speed(const BodyRecord<double>& a, const BodyRecord<double>& b, Vec3 c, Vec3 n) {
  const Vec3 ra = c - to_vec(a.p);
  const Vec3 rb = c - to_vec(b.p);
  const Vec3 u = (to_vec(a.v) + cross(to_vec(a.w), ra)) - (to_vec(b.v) + cross(to_vec(b.w), rb));
  return dot(u, n);
}

std::size_t debris_movable_count(std::size_t contacts) {
  return contacts == 0 ? 0 : std::max<std::size_t>(2, contacts / 2);
}

/// Half size of the debris box: about one body per 8 m^3.
double debris_half_extent(std::size_t movable) {
  return std::cbrt(static_cast<double>(std::max<std::size_t>(movable, 1)));
}

using detail::narrow;

}  // namespace

void draw_pair(const GenerateOptions& options, std::uint64_t k, BodyRecord<double>& a, BodyRecord<double>& b,
               ContactRecord<double>& contact) {
  CounterRng rng(options.seed, kPairStream, k);
  contact.a = static_cast<BodyIndex>(2 * k);
  contact.b = static_cast<BodyIndex>(2 * k + 1);
  // Re-drawn until the pair approaches, as the page's program does (its
  // "goto START"); the draws go on in the same stream, about two attempts
  // on average.
  for (;;) {
    draw_movable_body(rng, 100.0, a);
    draw_movable_body(rng, 100.0, b);
    fit_model(options.model, a);
    fit_model(options.model, b);
    const Vec3 ra = uniform_vec(rng, -2.0, 2.0);
    const Vec3 rb = uniform_vec(rng, -2.0, 2.0);
    const Vec3 n = unit_vec(rng);
    const Vec3 c = to_vec(a.p) + ra;
    store(c, contact.c);
    store(c - rb, b.p);
    store(n, contact.n);
    contact.e = rng.uniform();
    const double mu = rng.uniform();
    contact.mu = options.friction ? mu : 0.0;
    if (approach_speed(a, b, c, n) < -kMinApproachSpeed) return;
  }
}

std::size_t debris_body_count(std::size_t contacts) { return debris_movable_count(contacts) + 1; }

void draw_debris_body(const GenerateOptions& options, std::size_t contacts, std::uint64_t i, BodyRecord<double>& body) {
  const std::size_t movable = debris_movable_count(contacts);
  const double half = debris_half_extent(movable);
  if (i >= movable) {
    // The ground: immovable, at rest, just below the debris box.
    const double inf = std::numeric_limits<double>::infinity();
    body = BodyRecord<double>{};
    body.m = inf;
    body.I[0] = body.I[1] = body.I[2] = inf;
    body.p[1] = -half - 1.0;
    return;
  }
  CounterRng rng(options.seed, kDebrisBodyStream, i);
  draw_movable_body(rng, half, body);
  fit_model(options.model, body);
}

void draw_debris_contact(const GenerateOptions& options, std::size_t contacts, std::uint64_t k,
                         ContactRecord<double>& contact) {
  const std::size_t movable = debris_movable_count(contacts);
  CounterRng rng(options.seed, kDebrisContactStream, k);
  contact.a = static_cast<BodyIndex>(rng.below(movable));
  if (k % 4 == 3) {
    contact.b = static_cast<BodyIndex>(movable);  // every fourth contact is with the ground
  } else {
    const auto other = static_cast<BodyIndex>(rng.below(movable - 1));
    contact.b = other >= contact.a ? other + 1 : other;  // distinct from a, uniform
  }
  BodyRecord<double> a, b;
  draw_debris_body(options, contacts, contact.a, a);
  draw_debris_body(options, contacts, contact.b, b);
  // The contact point lies within a unit box around a's centre.
  const Vec3 c = to_vec(a.p) + uniform_vec(rng, -1.0, 1.0);
  store(c, contact.c);
  // A random normal, flipped so that the initial state approaches; re-drawn
  // when nearly tangent so the approach survives rounding to float.
  for (;;) {
    Vec3 n = unit_vec(rng);
    const double vn = approach_speed(a, b, c, n);
    if (std::fabs(vn) > kMinApproachSpeed) {
      if (vn > 0) n = {-n.x, -n.y, -n.z};
      store(n, contact.n);
      break;
    }
  }
  contact.e = rng.uniform();
  const double mu = rng.uniform();
  contact.mu = options.friction ? mu : 0.0;
}

template <class T>
Scene<T> generate_pairs(std::size_t pairs, const GenerateOptions& options) {
  Scene<T> scene;
  scene.bodies.resize(2 * pairs);
  scene.contacts.resize(pairs);
  // set() writes element i only, so disjoint ranges may run in parallel.
  oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, pairs, 4096),
                            [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                              BodyRecord<double> a, b;
                              ContactRecord<double> c;
                              for (std::size_t k = r.begin(); k != r.end(); ++k) {
                                draw_pair(options, k, a, b, c);
                                scene.bodies.set(2 * k, narrow<T>(a));
                                scene.bodies.set(2 * k + 1, narrow<T>(b));
                                scene.contacts.set(k, narrow<T>(c));
                              }
                            });
  return scene;
}

template <class T>
Scene<T> generate_debris(std::size_t contacts, const GenerateOptions& options) {
  Scene<T> scene;
  const std::size_t bodies = debris_body_count(contacts);
  scene.bodies.resize(bodies);
  scene.contacts.resize(contacts);
  oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, bodies, 4096),
                            [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                              BodyRecord<double> body;
                              for (std::size_t i = r.begin(); i != r.end(); ++i) {
                                draw_debris_body(options, contacts, i, body);
                                scene.bodies.set(i, narrow<T>(body));
                              }
                            });
  oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, contacts, 4096),
                            [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                              ContactRecord<double> c;
                              for (std::size_t k = r.begin(); k != r.end(); ++k) {
                                draw_debris_contact(options, contacts, k, c);
                                scene.contacts.set(k, narrow<T>(c));
                              }
                            });
  return scene;
}

template Scene<float> generate_pairs<float>(std::size_t, const GenerateOptions&);
template Scene<double> generate_pairs<double>(std::size_t, const GenerateOptions&);
template Scene<float> generate_debris<float>(std::size_t, const GenerateOptions&);
template Scene<double> generate_debris<double>(std::size_t, const GenerateOptions&);

}  // namespace collide
