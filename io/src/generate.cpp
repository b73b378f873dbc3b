// generate.cpp - the random "pairs", "debris", "pile" and "chain" scenes of
// collide/io/generate.hpp, whole: each scene's items drawn by its own file
// (io/src/generate/: pairs.cpp, debris.cpp, pile.cpp, chain.cpp, over the
// shared draws of generate/draws.hpp) and stored in T, in parallel.
//
// Design notes
// ------------
// * Every item is a pure function of (seed, k) (generate/draws.hpp), so a
//   whole scene is its items drawn in any order: disjoint ranges run in
//   parallel and the scene is the same bit for bit whatever the thread
//   count, and the same as the streamed files of `collide gen`, which draw
//   the items through the same functions in chunks.
// * The whole-scene entry points are here, apart from the items, so that a
//   scene kind's file holds what its scene is and this file how a scene is
//   assembled. The limits of the counts are checked here too, where a
//   scene of that count is allocated; the item draws take their count as
//   given (`collide gen` checks it against max_scene_count first).
#include "collide/io/generate.hpp"

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include "generate/pile.hpp"

namespace collide {
namespace {

using detail::narrow;
using generate_detail::draw_pile_contact_at;
using generate_detail::IndexPermutation;

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
