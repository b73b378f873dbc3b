// generate/pile.hpp - the pieces of the pile scene that other files of the
// generator use (private to the library): the lattice boxes and their face
// contacts, which the chain draws too (chain.cpp), and the pile's contact
// order, which generate.cpp walks for a whole scene.
//
// Design notes
// ------------
// * The chain is drawn by the pile's code (draw_box, draw_face_contact) so
//   that the two scenes share their margins and their tests' reasoning; the
//   constants below are the margin's terms, for both.
// * The shuffle is a permutation of the contact indices rather than of the
//   contacts, so that contact k stays a pure function of (seed, side, k);
//   generate_pile builds it once for the scene where draw_pile_contact
//   builds it per contact.
#pragma once

#include <cstddef>
#include <cstdint>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/generate.hpp"
#include "collide/model.hpp"
#include "generate/draws.hpp"

namespace collide::generate_detail {

// Geometry and velocities of the pile (generate.hpp). The approach margin:
// a lattice neighbour pair closes at kPileCompression x 1 m = 1 m/s; the
// random linear parts change that by at most 2 kPileVelocityJitter and the
// spins by at most 2 x 2 kPileSpin kPileContactOffset (w . (r x n), where
// r x n holds the two face offsets), 0.6 m/s in all; the bottom layer falls
// onto the ground at 1 m/s, less 0.1 + 0.2. So every contact approaches by
// at least 0.4 m/s, far above float's rounding of speeds below 2000 m/s.
// The chain's neighbours close at the same 1 m/s (chain_velocity) and take
// the same jitter and spin, so the same margin holds for its contacts.
inline constexpr double kPileCompression = 1.0;     // [1/s]
inline constexpr double kPileVelocityJitter = 0.1;  // [m/s] per axis
inline constexpr double kPileSpin = 0.25;           // [rad/s] per axis
inline constexpr double kPileContactOffset = 0.4;   // [m] per face axis, within every face (edges >= 0.9 m)
inline constexpr double kPileMinEdge = 0.9;         // [m]
inline constexpr double kPileMaxEdge = 1.0;         // [m]
inline constexpr double kPileTilt = 0.05;           // [rad] per axis of the rotation vector

/// A box of the pile or the chain: mass, edges and the moments of a solid
/// box, a small tilt, centred at p, moving at `velocity` (the pile's
/// compression field, the chain's parity velocity) plus a small jitter,
/// spinning a little; fitted to the model after all of its draws.
void draw_box(CounterRng& rng, Vec3 p, Vec3 velocity, Model model, BodyRecord<double>& body);

/// Which body a pile contact joins to its box (side a).
enum class PileNeighbour { x, y, z, ground };

/// The point, normal, e and mu of the contact between the box centred at p
/// (side a) and its neighbour on `face` (side b): the point on the touching
/// face, offset within it along its two axes, the normal along the axis from
/// b towards a. The caller sets a and b.
void draw_face_contact(CounterRng& rng, Vec3 p, PileNeighbour face, bool friction, ContactRecord<double>& contact);

/// Contact q of the pile in cell order.
void draw_pile_contact_at(const GenerateOptions& options, std::size_t side, std::uint64_t q,
                          ContactRecord<double>& contact);

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

}  // namespace collide::generate_detail
