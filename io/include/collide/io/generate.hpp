// collide/io/generate.hpp - random scenes for tests, benchmarks and `collide gen`.
//
// Four scenes: "pairs" (independent pairs), "debris" (contacts between
// bodies picked at random, a ground body among them), "pile" (boxes on a
// lattice, each touching its neighbours, the bottom layer on the ground) and
// "chain" (boxes in a staircase, each touching the next, no ground: every
// contact depends on the one before).
// Draws follow the source page's test program: random masses, principal
// moments, orientations (a rotation vector), velocities, contact offsets and
// unit normals, re-drawn until the pair approaches. Every item is a pure
// function of (seed, k) through a counter-based generator, so the same seed
// gives the same scene whatever the thread count or chunking, and a file of
// ten million pairs can be written in a stream.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/scene.hpp"
#include "collide/model.hpp"

namespace collide {

struct GenerateOptions {
  std::uint64_t seed = 1;
  /// When true, mu is drawn uniformly from [0, 1]; otherwise mu = 0.
  bool friction = false;
  /// The body model the scene fits (model.hpp): rigid bodies as drawn;
  /// sphere: Iy = Iz = Ix; particle: infinite moments and w = 0. Every other
  /// draw is the same, so the scenes of the three models differ only there.
  Model model = Model::rigid;
  /// The pile scene only: its contacts in a random order (a permutation drawn
  /// from the seed) instead of broadphase cell order; every contact's values
  /// are the same. The pairs and debris contacts have no spatial order; the
  /// chain keeps its chain order.
  bool shuffle = false;
};

/// Pair k of the "pairs" scene in physical units: bodies a (id 2k) and b
/// (id 2k+1) and the contact between them, approaching (u . n < 0).
void draw_pair(const GenerateOptions& options, std::uint64_t k, BodyRecord<double>& a, BodyRecord<double>& b,
               ContactRecord<double>& contact);

/// The "pairs" scene: contact k joins bodies 2k and 2k+1; no body is shared.
template <class T>
Scene<T> generate_pairs(std::size_t pairs, const GenerateOptions& options = {});

/// The "debris" scene: `contacts` contacts over contacts/2 movable bodies
/// (random indices, so bodies are shared) plus one immovable ground body, the
/// last body, which is side b of 25% of the contacts. Every contact
/// approaches in the initial state.
template <class T>
Scene<T> generate_debris(std::size_t contacts, const GenerateOptions& options = {});

// The pieces of the debris scene, each a pure function of its arguments, so
// that `collide gen --debris` can stream the files in chunks.

/// Number of bodies of the debris scene: the movable ones plus the ground.
std::size_t debris_body_count(std::size_t contacts);
/// Body i of the debris scene with `contacts` contacts; the last body
/// (i == debris_body_count(contacts) - 1) is the immovable ground.
void draw_debris_body(const GenerateOptions& options, std::size_t contacts, std::uint64_t i, BodyRecord<double>& body);
/// Contact k of the debris scene, approaching in the initial state.
void draw_debris_contact(const GenerateOptions& options, std::size_t contacts, std::uint64_t k,
                         ContactRecord<double>& contact);

/// The "pile" scene: side^3 boxes on a cubic lattice of pitch 1 m, box
/// (ix, iy, iz) = body ix + side (iy + side iz) centred at (ix, iy, iz) + 0.5,
/// plus one immovable ground body (the last, inverse mass 0) under the bottom
/// layer. Each box touches its +x, +y and +z neighbours and the bottom layer
/// touches the ground, one contact per touching pair: 3 side^2 (side - 1) +
/// side^2 contacts. Box b of a contact is the +x, +y or +z neighbour or the
/// ground, the normal along the lattice axis from b towards a. The contact
/// point lies on the plane between the two centres, offset within the
/// touching face (up to 0.4 m along each face axis), off the line of centres,
/// so the rotational terms act and the rigid model is needed.
///
/// Boxes: mass in [0.1, 20) kg, edges in [0.9, 1) m, a box's principal
/// moments m (b^2 + c^2) / 12, tilted by a rotation vector of up to 0.05 rad
/// per axis. Velocities: the pile is compressed towards the ground under
/// its centre, v = -k (p - (side/2, side/2, -0.5)) with k = 1/s (so
/// neighbours close at 1 m/s and the bottom layer falls at 1 m/s), plus up to
/// 0.1 m/s per axis, and w up to 0.25 rad/s per axis: every contact
/// approaches by at least 0.4 m/s, also in float. e and mu are drawn as the
/// debris scene draws them.
///
/// Contacts in broadphase cell order: cell by cell (x fastest, then y, then
/// z), each cell's contacts with +x, +y, +z and the ground, the order a
/// uniform grid broadphase emits; options.shuffle permutes them. At most
/// kMaxPileSide boxes per side (body ids are 32-bit); std::invalid_argument
/// beyond.
template <class T>
Scene<T> generate_pile(std::size_t side, const GenerateOptions& options = {});

/// The largest pile: side^3 boxes and the ground have 32-bit ids.
inline constexpr std::size_t kMaxPileSide = 1625;

// The pieces of the pile scene, each a pure function of its arguments, so
// that `collide gen --pile` can stream the files in chunks.

/// Number of bodies of a pile: side^3 boxes plus the ground.
std::size_t pile_body_count(std::size_t side);
/// Number of contacts of a pile: 3 side^2 (side - 1) + side^2.
std::size_t pile_contact_count(std::size_t side);
/// The side of the largest pile with at most `contacts` contacts (0 when
/// contacts is 0): how a scene sized in contacts, like the report's, picks
/// its pile.
std::size_t pile_side_for_contacts(std::size_t contacts);
/// Body i of the pile of `side` boxes per side; the last body
/// (i == pile_body_count(side) - 1) is the immovable ground.
void draw_pile_body(const GenerateOptions& options, std::size_t side, std::uint64_t i, BodyRecord<double>& body);
/// Contact k of the pile (after the shuffle, when options.shuffle is set),
/// approaching in the initial state.
void draw_pile_contact(const GenerateOptions& options, std::size_t side, std::uint64_t k,
                       ContactRecord<double>& contact);

/// The "chain" scene: contacts + 1 boxes in a staircase on the pile's
/// lattice (pitch 1 m), and no ground: every body is movable. Box i sits in
/// cell ((i + 1) / 2, i / 2, 0), centred at the cell + 0.5 in each axis, so
/// box i + 1 is the +x neighbour of box i for even i and its +y neighbour for
/// odd i: cells (0, 0), (1, 0), (1, 1), (2, 1), (2, 2), ... Boxes two or more
/// apart in the chain meet only diagonally, never on a face. Contact k joins
/// box k (side a) and box k + 1 (side b), in chain order, drawn as the pile's
/// +x (k even) or +y (k odd) contact of box k: on the plane between the two
/// centres, offset within the touching face by up to 0.4 m along each face
/// axis (off the line of centres, so the rigid model is needed), the normal
/// from b towards a, (-1, 0, 0) or (0, -1, 0). Each box but the ends is in
/// two contacts, so the level schedule (collide/schedule.hpp) makes one batch
/// per contact and the law runs sequentially through every contact: a
/// stand-in for a rope, a column or a stack, the scene with the longest
/// dependency chain there is, against the pairs scene's none.
///
/// Boxes are drawn as the pile's are (mass, edges, moments, tilt, velocity
/// jitter and spin: generate_pile) but for their velocity: even boxes move at
/// (0.5, -0.5, 0) m/s and odd ones at (-0.5, 0.5, 0) m/s, plus up to 0.1 m/s
/// per axis, so no speed exceeds 0.6 m/s per axis whatever the chain's
/// length. Neighbours have opposite parities: along the axis of their step
/// they close at 1 m/s, as the pile's neighbours do, and the pile's jitter
/// and spin take at most 0.6 m/s of that (2 x 0.1 m/s of jitter, 2 x 0.2 m/s
/// of spin times face offset): every contact approaches by at least 0.4 m/s
/// in double, whatever the chain's length. Float
/// rounds the velocities by less than 1e-7 m/s; it rounds the positions,
/// which reach contacts/2 m along x and y, to an ulp of the coordinate, and
/// a contact point moved within its face costs the margin up to a quarter of
/// that ulp: in float every contact approaches by at least 0.38 m/s up to
/// 2^20 contacts, 0.33 m/s up to 2^22 (the benchmark's largest chain) and
/// 0.27 m/s up to 2^23; from about 2^24 contacts on, float no longer holds
/// the box centres exactly. e and mu are drawn as the pile draws them; options.shuffle does
/// not apply. At most kMaxChainContacts contacts (body ids are 32-bit);
/// std::invalid_argument beyond.
template <class T>
Scene<T> generate_chain(std::size_t contacts, const GenerateOptions& options = {});

/// The longest chain: contacts + 1 boxes have 32-bit ids (2^32 - 2 contacts,
/// the most a Schedule takes).
inline constexpr std::size_t kMaxChainContacts = (std::size_t{1} << 32) - 2;

/// The most pairs: 2N bodies have 32-bit ids.
inline constexpr std::size_t kMaxPairs = 0x7FFFFFFF;
/// The most debris contacts: N / 2 + 1 bodies have 32-bit ids.
inline constexpr std::size_t kMaxDebrisContacts = 0xFFFFFFFF;

/// The largest count of scene `kind` ("pairs", "debris", "pile" or "chain";
/// 0 for another) that `collide gen --<kind> N` and collide.generate(kind,
/// n) take: kMaxPairs, kMaxDebrisContacts, kMaxPileSide (boxes per side)
/// and kMaxChainContacts. The least is 1 for every scene: no scene is empty.
inline std::size_t max_scene_count(std::string_view kind) {
  return kind == "pairs"    ? kMaxPairs
         : kind == "debris" ? kMaxDebrisContacts
         : kind == "pile"   ? kMaxPileSide
         : kind == "chain"  ? kMaxChainContacts
                            : 0;
}

// The pieces of the chain scene, each a pure function of its arguments, so
// that a chain can be written in a stream.

/// Number of bodies of a chain of `contacts` contacts: contacts + 1 boxes.
std::size_t chain_body_count(std::size_t contacts);
/// Body i of the chain of `contacts` contacts (box i, i < contacts + 1).
void draw_chain_body(const GenerateOptions& options, std::size_t contacts, std::uint64_t i, BodyRecord<double>& body);
/// Contact k of the chain (between boxes k and k + 1), approaching in the
/// initial state.
void draw_chain_contact(const GenerateOptions& options, std::size_t contacts, std::uint64_t k,
                        ContactRecord<double>& contact);

}  // namespace collide
