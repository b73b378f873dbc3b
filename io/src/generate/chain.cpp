// generate/chain.cpp - the "chain" scene of collide/io/generate.hpp: boxes in a
// staircase, each touching the next, no ground.
//
// Design notes
// ------------
// * The chain is a staircase of the pile's boxes with no ground: box k + 1
//   is the +x (k even) or +y (k odd) lattice neighbour of box k, its boxes
//   and contacts are drawn by the pile's code (draw_box, draw_face_contact,
//   generate/pile.hpp), in streams of its own, so the two scenes share their
//   margins and their tests' reasoning but no values.
// * Instead of the pile's compression field, which closes n neighbours in a
//   row only with speeds growing along it, the chain's boxes move at
//   +-(0.5, -0.5, 0) m/s by parity: the staircase alternates x and y steps,
//   so every neighbour pair closes at 1 m/s along its normal with speeds
//   that do not grow with the chain.
#include <cstddef>
#include <cstdint>

#include "collide/io/generate.hpp"
#include "generate/draws.hpp"
#include "generate/pile.hpp"

namespace collide {
namespace {

using generate_detail::CounterRng;
using generate_detail::draw_box;
using generate_detail::draw_face_contact;
using generate_detail::kChainBodyStream;
using generate_detail::kChainContactStream;
using generate_detail::PileNeighbour;
using generate_detail::Vec3;

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

}  // namespace

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

}  // namespace collide
