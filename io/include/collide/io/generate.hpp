// collide/io/generate.hpp - random scenes for tests, benchmarks and `collide gen`.
//
// Draws follow the source page's test program: random masses, principal
// moments, orientations (a rotation vector), velocities, contact offsets and
// unit normals, re-drawn until the pair approaches. Every pair is a pure
// function of (seed, k) through a counter-based generator, so the same seed
// gives the same scene whatever the thread count or chunking, and a file of
// ten million pairs can be written in a stream.
#pragma once

#include <cstddef>
#include <cstdint>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/model.hpp"
#include "collide/io/scene.hpp"

namespace collide {

struct GenerateOptions {
  std::uint64_t seed = 1;
  /// When true, mu is drawn uniformly from [0, 1]; otherwise mu = 0.
  bool friction = false;
  /// The body model the scene fits (model.hpp): rigid bodies as drawn;
  /// sphere: Iy = Iz = Ix; particle: infinite moments and w = 0. Every other
  /// draw is the same, so the scenes of the three models differ only there.
  Model model = Model::rigid;
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

}  // namespace collide
