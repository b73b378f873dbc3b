// support/generated_scenes.hpp - the io generators' scenes as the solver's
// tests draw them: one call names the kind, the size, the seed and the
// friction, so two test files that want the same debris get the same one.
#pragma once

#include <cstddef>
#include <cstdint>

#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"

namespace collide::test {

/// generate_debris's scene of `contacts` contacts from `seed`, with mu drawn
/// when `friction`, in the bodies of `model`.
template <class T>
Scene<T> generated_debris(std::size_t contacts, std::uint64_t seed, bool friction, Model model = Model::rigid) {
  GenerateOptions o;
  o.seed = seed;
  o.friction = friction;
  o.model = model;
  return generate_debris<T>(contacts, o);
}

}  // namespace collide::test
