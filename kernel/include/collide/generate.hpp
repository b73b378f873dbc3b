// collide/generate.hpp - random scenes for tests, benchmarks and `collide gen`.
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
#include "collide/scene.hpp"

namespace collide {

struct GenerateOptions {
  std::uint64_t seed = 1;
  /// When true, mu is drawn uniformly from [0, 1]; otherwise mu = 0.
  bool friction = false;
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

}  // namespace collide
