// generate.cpp - the random "pairs", "debris", "pile" and "chain" scenes.
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
// * The pile cannot re-draw a contact until it approaches: its boxes are
//   shared by up to seven contacts. It approaches by construction instead: a
//   compression field closes every lattice neighbour pair at 1 m/s, and the
//   random parts of the velocities are bounded so that they take at most
//   0.6 m/s of it (generate.hpp; the test checks every contact). Its
//   contacts are drawn by cell-order index q, so that the shuffle, a
//   permutation of the indices (a Feistel network keyed by the seed,
//   cycle-walked into [0, count)), moves contacts without changing them and
//   contact k is still a pure function of (seed, side, k).
// * The chain is a staircase of the pile's boxes with no ground: box k + 1
//   is the +x (k even) or +y (k odd) lattice neighbour of box k, its boxes
//   and contacts are drawn by the pile's code (draw_box, draw_face_contact),
//   in streams of its own, so the two scenes share their margins and their
//   tests' reasoning but no values. Instead of the pile's compression field,
//   which closes n neighbours in a row only with speeds growing along it,
//   the chain's boxes move at +-(0.5, -0.5, 0) m/s by parity: the staircase
//   alternates x and y steps, so every neighbour pair closes at 1 m/s along
//   its normal with speeds that do not grow with the chain.
#include "collide/io/generate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

namespace collide {
namespace {

constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ULL;
// Stream salts: distinct scenes and item kinds never share a key.
constexpr std::uint64_t kPairStream = 0x7061697273000001ULL;
constexpr std::uint64_t kDebrisBodyStream = 0x6465627269730002ULL;
constexpr std::uint64_t kDebrisContactStream = 0x6465627269730003ULL;
constexpr std::uint64_t kPileBodyStream = 0x70696c6500000004ULL;
constexpr std::uint64_t kPileContactStream = 0x70696c6500000005ULL;
constexpr std::uint64_t kPileShuffleStream = 0x70696c6500000006ULL;
constexpr std::uint64_t kChainBodyStream = 0x636861696e000007ULL;
constexpr std::uint64_t kChainContactStream = 0x636861696e000008ULL;

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

/// The unit quaternion (w, x, y, z) of a rotation vector (angle = |rv|).
void store_rotation(Vec3 rv, double* q) {
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
void draw_movable_body(CounterRng& rng, double half_extent, BodyRecord<double>& body) {
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

/// The immovable ground: infinite mass and moments, at rest at p.
void store_ground(Vec3 p, BodyRecord<double>& body) {
  const double inf = std::numeric_limits<double>::infinity();
  body = BodyRecord<double>{};
  body.m = inf;
  body.I[0] = body.I[1] = body.I[2] = inf;
  store(p, body.p);
}

// -- the pile ----------------------------------------------------------------

// Geometry and velocities of the pile (generate.hpp). The approach margin:
// a lattice neighbour pair closes at kPileCompression x 1 m = 1 m/s; the
// random linear parts change that by at most 2 kPileVelocityJitter and the
// spins by at most 2 x 2 kPileSpin kPileContactOffset (w . (r x n), where
// r x n holds the two face offsets), 0.6 m/s in all; the bottom layer falls
// onto the ground at 1 m/s, less 0.1 + 0.2. So every contact approaches by
// at least 0.4 m/s, far above float's rounding of speeds below 2000 m/s.
// The chain's neighbours close at the same 1 m/s (chain_velocity) and take
// the same jitter and spin, so the same margin holds for its contacts.
constexpr double kPileCompression = 1.0;     // [1/s]
constexpr double kPileVelocityJitter = 0.1;  // [m/s] per axis
constexpr double kPileSpin = 0.25;           // [rad/s] per axis
constexpr double kPileContactOffset = 0.4;   // [m] per face axis, within every face (edges >= 0.9 m)
constexpr double kPileMinEdge = 0.9;         // [m]
constexpr double kPileMaxEdge = 1.0;         // [m]
constexpr double kPileTilt = 0.05;           // [rad] per axis of the rotation vector

/// Where the pile is compressed towards, and the ground's centre: under the
/// middle of the pile, half a pitch below the ground plane z = 0.
Vec3 pile_centre(std::size_t side) { return {0.5 * static_cast<double>(side), 0.5 * static_cast<double>(side), -0.5}; }

/// The lattice point of box i: its centre.
Vec3 pile_box_centre(std::size_t side, std::uint64_t i) {
  const std::uint64_t ix = i % side;
  const std::uint64_t iy = (i / side) % side;
  const std::uint64_t iz = i / side / side;
  return {static_cast<double>(ix) + 0.5, static_cast<double>(iy) + 0.5, static_cast<double>(iz) + 0.5};
}

/// The pile's compression field at p: towards `towards` at kPileCompression.
Vec3 compression_velocity(Vec3 p, Vec3 towards) {
  return {-kPileCompression * (p.x - towards.x), -kPileCompression * (p.y - towards.y),
          -kPileCompression * (p.z - towards.z)};
}

/// A box of the pile or the chain: mass, edges and the moments of a solid
/// box, a small tilt, centred at p, moving at `velocity` (the pile's
/// compression field, the chain's parity velocity) plus a small jitter,
/// spinning a little; fitted to the model after all of its draws.
void draw_box(CounterRng& rng, Vec3 p, Vec3 velocity, Model model, BodyRecord<double>& body) {
  body.m = rng.uniform(0.1, 20.0);
  const Vec3 edge = uniform_vec(rng, kPileMinEdge, kPileMaxEdge);
  // A solid box's principal moments about its centre, along its edges.
  body.I[0] = body.m * (edge.y * edge.y + edge.z * edge.z) / 12.0;
  body.I[1] = body.m * (edge.x * edge.x + edge.z * edge.z) / 12.0;
  body.I[2] = body.m * (edge.x * edge.x + edge.y * edge.y) / 12.0;
  store_rotation(uniform_vec(rng, -kPileTilt, kPileTilt), body.q);
  store(p, body.p);
  const Vec3 jitter = uniform_vec(rng, -kPileVelocityJitter, kPileVelocityJitter);
  store(velocity + jitter, body.v);
  store(uniform_vec(rng, -kPileSpin, kPileSpin), body.w);
  fit_model(model, body);
}

/// Which body a pile contact joins to its box (side a).
enum class PileNeighbour { x, y, z, ground };

/// The point, normal, e and mu of the contact between the box centred at p
/// (side a) and its neighbour on `face` (side b): the point on the touching
/// face, offset within it along its two axes, the normal along the axis from
/// b towards a. The caller sets a and b.
void draw_face_contact(CounterRng& rng, Vec3 p, PileNeighbour face, bool friction, ContactRecord<double>& contact) {
  // Offsets within the touching face, along its two axes.
  const double t1 = rng.uniform(-kPileContactOffset, kPileContactOffset);
  const double t2 = rng.uniform(-kPileContactOffset, kPileContactOffset);
  Vec3 c{}, n{};
  switch (face) {
    case PileNeighbour::x:
      c = {p.x + 0.5, p.y + t1, p.z + t2};
      n = {-1.0, 0.0, 0.0};
      break;
    case PileNeighbour::y:
      c = {p.x + t1, p.y + 0.5, p.z + t2};
      n = {0.0, -1.0, 0.0};
      break;
    case PileNeighbour::z:
      c = {p.x + t1, p.y + t2, p.z + 0.5};
      n = {0.0, 0.0, -1.0};
      break;
    case PileNeighbour::ground:
      c = {p.x + t1, p.y + t2, p.z - 0.5};
      n = {0.0, 0.0, 1.0};
      break;
  }
  store(c, contact.c);
  store(n, contact.n);
  contact.e = rng.uniform();
  const double mu = rng.uniform();
  contact.mu = friction ? mu : 0.0;
}

/// Contacts of one z layer: its +x and +y contacts, +z below the top layer,
/// and the ground under the bottom one.
std::uint64_t pile_layer_contacts(std::uint64_t side, bool up, bool ground) {
  return 2 * side * (side - 1) + (static_cast<std::uint64_t>(up) + static_cast<std::uint64_t>(ground)) * side * side;
}

/// Contact q of the pile in cell order: its box and the neighbour, found by
/// counting the contacts of whole layers, rows and cells before it (a cell's
/// contacts are +x, +y, +z, ground, each where it exists).
void locate_pile_contact(std::uint64_t side, std::uint64_t q, std::uint64_t& box, PileNeighbour& neighbour) {
  const std::uint64_t s = side;
  std::uint64_t iz = 0, r = q;
  bool up = s > 1, ground = true;
  if (const std::uint64_t bottom = pile_layer_contacts(s, up, true); r >= bottom) {
    r -= bottom;
    ground = false;
    const std::uint64_t middle_layers = s >= 3 ? s - 2 : 0;
    const std::uint64_t middle = pile_layer_contacts(s, true, false);
    if (r < middle_layers * middle) {
      iz = 1 + r / middle;
      r %= middle;
    } else {
      iz = s - 1;
      r -= middle_layers * middle;
      up = false;
    }
  }
  const std::uint64_t zg = static_cast<std::uint64_t>(up) + static_cast<std::uint64_t>(ground);
  // A row below the last has s (2 + zg) - 1 contacts (its last cell has no +x).
  const std::uint64_t row = s * (2 + zg) - 1;
  std::uint64_t iy = 0;
  bool has_y = true;
  if (r < (s - 1) * row) {
    iy = r / row;
    r %= row;
  } else {
    iy = s - 1;
    r -= (s - 1) * row;
    has_y = false;
  }
  const std::uint64_t per_cell = 1 + static_cast<std::uint64_t>(has_y) + zg;
  const std::uint64_t ix = r / per_cell;
  std::uint64_t slot = r % per_cell;
  PileNeighbour kinds[4];
  std::uint64_t count = 0;
  if (ix + 1 < s) kinds[count++] = PileNeighbour::x;
  if (has_y) kinds[count++] = PileNeighbour::y;
  if (up) kinds[count++] = PileNeighbour::z;
  if (ground) kinds[count++] = PileNeighbour::ground;
  slot = std::min(slot, count - 1);  // unreachable for q < pile_contact_count(side)
  box = ix + s * (iy + s * iz);
  neighbour = kinds[slot];
}

/// Contact q of the pile in cell order.
void draw_pile_contact_at(const GenerateOptions& options, std::size_t side, std::uint64_t q,
                          ContactRecord<double>& contact) {
  std::uint64_t box = 0;
  PileNeighbour neighbour = PileNeighbour::x;
  locate_pile_contact(side, q, box, neighbour);
  const std::uint64_t s = side;
  std::uint64_t other = 0;
  switch (neighbour) {
    case PileNeighbour::x:
      other = box + 1;
      break;
    case PileNeighbour::y:
      other = box + s;
      break;
    case PileNeighbour::z:
      other = box + s * s;
      break;
    case PileNeighbour::ground:
      other = s * s * s;
      break;
  }
  contact.a = static_cast<BodyIndex>(box);
  contact.b = static_cast<BodyIndex>(other);
  CounterRng rng(options.seed, kPileContactStream, q);
  draw_face_contact(rng, pile_box_centre(side, box), neighbour, options.friction, contact);
}

/// A bijection of [0, count) drawn from the seed: a Feistel network on the
/// smallest even number of bits that holds count (a bijection of [0, 4^h)),
/// cycle-walked: an image outside [0, count) is mapped again until it lands
/// inside, which keeps it a bijection of [0, count) and takes fewer than 4
/// steps on average since 4^h < 4 count.
class IndexPermutation {
 public:
  IndexPermutation(std::uint64_t seed, std::uint64_t count) : count_(count) {
    while (half_bits_ < 32 && (std::uint64_t{1} << (2 * half_bits_)) < count) ++half_bits_;
    mask_ = (std::uint64_t{1} << half_bits_) - 1;
    for (int round = 0; round < kRounds; ++round) {
      keys_[round] =
          splitmix64(splitmix64(seed ^ kPileShuffleStream) + count * kGolden + static_cast<std::uint64_t>(round));
    }
  }
  std::uint64_t operator()(std::uint64_t i) const {
    std::uint64_t x = i;
    do {
      x = feistel(x);
    } while (x >= count_);
    return x;
  }

 private:
  static constexpr int kRounds = 6;
  std::uint64_t feistel(std::uint64_t x) const {
    std::uint64_t left = x >> half_bits_, right = x & mask_;
    for (const std::uint64_t key : keys_) {
      const std::uint64_t next = left ^ (splitmix64(key ^ right) & mask_);
      left = right;
      right = next;
    }
    return (left << half_bits_) | right;
  }
  std::uint64_t count_;
  unsigned half_bits_ = 1;
  std::uint64_t mask_ = 1;
  std::uint64_t keys_[kRounds] = {};
};

// -- the chain ---------------------------------------------------------------

/// The centre of box i of the chain: its lattice cell is ((i + 1) / 2, i / 2,
/// 0), so box i + 1 is box i's +x neighbour for even i and its +y neighbour
/// for odd i (the cells' x + y is i: boxes two or more apart in the chain
/// meet at most along an edge, never on a face).
Vec3 chain_box_centre(std::uint64_t i) {
  const std::uint64_t x = (i + 1) / 2;
  const std::uint64_t y = i / 2;
  return {static_cast<double>(x) + 0.5, static_cast<double>(y) + 0.5, 0.5};
}

/// Which neighbour of box k the chain's next box is, and so which of the
/// pile's face contacts contact k is: +x for even k, +y for odd k.
PileNeighbour chain_step(std::uint64_t k) { return k % 2 == 0 ? PileNeighbour::x : PileNeighbour::y; }

/// A chain box's speed along x and along y before its jitter [m/s]:
/// neighbours move opposite ways, so they close at 2 x 0.5 = 1 m/s, the
/// pile's closing speed.
constexpr double kChainSpeed = 0.5;

/// The velocity of box i of the chain before its jitter: (0.5, -0.5, 0) for
/// even i, its opposite for odd i. Neighbours have opposite parities, so
/// along the axis of their step (x after an even box, y after an odd one)
/// each moves towards the other and the pair closes at 1 m/s; across it they
/// slide past each other, which the normal does not see.
Vec3 chain_velocity(std::uint64_t i) {
  const double s = i % 2 == 0 ? kChainSpeed : -kChainSpeed;
  return {s, -s, 0.0};
}

void check_chain_contacts(std::size_t contacts) {
  if (contacts > kMaxChainContacts) {
    throw std::invalid_argument("generate_chain: " + std::to_string(contacts) + " contacts, at most " +
                                std::to_string(kMaxChainContacts) + " (body ids are 32-bit)");
  }
}

void check_pile_side(std::size_t side) {
  if (side > kMaxPileSide) {
    throw std::invalid_argument("generate_pile: " + std::to_string(side) + " boxes per side, at most " +
                                std::to_string(kMaxPileSide) + " (body ids are 32-bit)");
  }
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
    store_ground({0.0, -half - 1.0, 0.0}, body);
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

std::size_t pile_body_count(std::size_t side) { return side * side * side + 1; }

std::size_t pile_contact_count(std::size_t side) { return side == 0 ? 0 : 3 * side * side * (side - 1) + side * side; }

std::size_t pile_side_for_contacts(std::size_t contacts) {
  std::size_t side = 0;
  while (side < kMaxPileSide && pile_contact_count(side + 1) <= contacts) ++side;
  return side;
}

void draw_pile_body(const GenerateOptions& options, std::size_t side, std::uint64_t i, BodyRecord<double>& body) {
  if (i >= static_cast<std::uint64_t>(side) * side * side) {
    store_ground(pile_centre(side), body);
    return;
  }
  CounterRng rng(options.seed, kPileBodyStream, i);
  const Vec3 p = pile_box_centre(side, i);
  draw_box(rng, p, compression_velocity(p, pile_centre(side)), options.model, body);
}

void draw_pile_contact(const GenerateOptions& options, std::size_t side, std::uint64_t k,
                       ContactRecord<double>& contact) {
  const std::uint64_t q = options.shuffle ? IndexPermutation(options.seed, pile_contact_count(side))(k) : k;
  draw_pile_contact_at(options, side, q, contact);
}

std::size_t chain_body_count(std::size_t contacts) { return contacts + 1; }

void draw_chain_body(const GenerateOptions& options, std::size_t /*contacts*/, std::uint64_t i,
                     BodyRecord<double>& body) {
  CounterRng rng(options.seed, kChainBodyStream, i);
  draw_box(rng, chain_box_centre(i), chain_velocity(i), options.model, body);
}

void draw_chain_contact(const GenerateOptions& options, std::size_t /*contacts*/, std::uint64_t k,
                        ContactRecord<double>& contact) {
  contact.a = static_cast<BodyIndex>(k);
  contact.b = static_cast<BodyIndex>(k + 1);
  CounterRng rng(options.seed, kChainContactStream, k);
  draw_face_contact(rng, chain_box_centre(k), chain_step(k), options.friction, contact);
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

namespace {

/// A scene of `bodies` bodies and `contacts` contacts, each drawn in double by
/// draw_body(i, body) and draw_contact(k, contact) and stored in T. set()
/// writes element i only, so disjoint ranges run in parallel.
template <class T, class DrawBody, class DrawContact>
Scene<T> draw_scene(std::size_t bodies, std::size_t contacts, const DrawBody& draw_body,
                    const DrawContact& draw_contact) {
  Scene<T> scene;
  scene.bodies.resize(bodies);
  scene.contacts.resize(contacts);
  oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, bodies, 4096),
                            [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                              BodyRecord<double> body;
                              for (std::size_t i = r.begin(); i != r.end(); ++i) {
                                draw_body(i, body);
                                scene.bodies.set(i, narrow<T>(body));
                              }
                            });
  oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, contacts, 4096),
                            [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                              ContactRecord<double> c;
                              for (std::size_t k = r.begin(); k != r.end(); ++k) {
                                draw_contact(k, c);
                                scene.contacts.set(k, narrow<T>(c));
                              }
                            });
  return scene;
}

}  // namespace

template <class T>
Scene<T> generate_debris(std::size_t contacts, const GenerateOptions& options) {
  return draw_scene<T>(
      debris_body_count(contacts), contacts,
      [&](std::size_t i, BodyRecord<double>& body) { draw_debris_body(options, contacts, i, body); },
      [&](std::size_t k, ContactRecord<double>& c) { draw_debris_contact(options, contacts, k, c); });
}

template <class T>
Scene<T> generate_pile(std::size_t side, const GenerateOptions& options) {
  check_pile_side(side);
  const std::size_t contacts = pile_contact_count(side);
  // The permutation once for the scene rather than once per contact.
  const IndexPermutation shuffle(options.seed, contacts);
  return draw_scene<T>(
      pile_body_count(side), contacts,
      [&](std::size_t i, BodyRecord<double>& body) { draw_pile_body(options, side, i, body); },
      [&](std::size_t k, ContactRecord<double>& c) {
        draw_pile_contact_at(options, side, options.shuffle ? shuffle(k) : k, c);
      });
}

template <class T>
Scene<T> generate_chain(std::size_t contacts, const GenerateOptions& options) {
  check_chain_contacts(contacts);
  return draw_scene<T>(
      chain_body_count(contacts), contacts,
      [&](std::size_t i, BodyRecord<double>& body) { draw_chain_body(options, contacts, i, body); },
      [&](std::size_t k, ContactRecord<double>& c) { draw_chain_contact(options, contacts, k, c); });
}

template Scene<float> generate_pairs<float>(std::size_t, const GenerateOptions&);
template Scene<double> generate_pairs<double>(std::size_t, const GenerateOptions&);
template Scene<float> generate_debris<float>(std::size_t, const GenerateOptions&);
template Scene<double> generate_debris<double>(std::size_t, const GenerateOptions&);
template Scene<float> generate_pile<float>(std::size_t, const GenerateOptions&);
template Scene<double> generate_pile<double>(std::size_t, const GenerateOptions&);
template Scene<float> generate_chain<float>(std::size_t, const GenerateOptions&);
template Scene<double> generate_chain<double>(std::size_t, const GenerateOptions&);

}  // namespace collide
