// generate/pile.cpp - the "pile" scene of collide/io/generate.hpp: boxes on a
// lattice, each touching its neighbours, the bottom layer on the ground, and
// the boxes and face contacts the chain is drawn from too.
//
// Design notes
// ------------
// * The pile cannot re-draw a contact until it approaches: its boxes are
//   shared by up to seven contacts. It approaches by construction instead: a
//   compression field closes every lattice neighbour pair at 1 m/s, and the
//   random parts of the velocities are bounded so that they take at most
//   0.6 m/s of it (generate.hpp, generate/pile.hpp; the test checks every
//   contact).
// * Its contacts are drawn by cell-order index q, so that the shuffle, a
//   permutation of the indices (IndexPermutation: a Feistel network keyed by
//   the seed, cycle-walked into [0, count)), moves contacts without changing
//   them and contact k is still a pure function of (seed, side, k).
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "collide/io/generate.hpp"
#include "generate/draws.hpp"
#include "generate/pile.hpp"

namespace collide {
namespace {

using generate_detail::CounterRng;
using generate_detail::draw_box;
using generate_detail::draw_pile_contact_at;
using generate_detail::IndexPermutation;
using generate_detail::kPileBodyStream;
using generate_detail::kPileCompression;
using generate_detail::PileNeighbour;
using generate_detail::store_ground;
using generate_detail::Vec3;

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

}  // namespace

namespace generate_detail {

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

}  // namespace generate_detail

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

}  // namespace collide
