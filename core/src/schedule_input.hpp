// schedule_input.hpp - what the passes of a schedule read (private to the
// library): the contacts' body indices and the bodies' inverse masses,
// whatever the body layout, and how far ahead the passes prefetch.
#pragma once

#include <cstddef>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"

namespace collide::detail {

/// The contacts a pass reads: their body indices, and the body count every
/// index must stay below.
struct ContactIndices {
  const BodyIndex* a = nullptr;
  const BodyIndex* b = nullptr;
  std::size_t count = 0;
  std::size_t body_count = 0;
};

/// Body i's inverse mass at data[i * stride]: 1 for SoA views and a rigid
/// packed view's dense array, the record size for other packed views.
template <class T>
struct InverseMasses {
  const T* data = nullptr;
  std::size_t stride = 1;

  [[nodiscard]] bool immovable(std::size_t i) const { return is_immovable(data[i * stride]); }
};

/// Contacts ahead whose bodies' table entries the level and colour passes
/// prefetch: fewer leave misses exposed, more gain nothing (measured on the
/// debris scene: docs/decisions/0015-the-schedules-level-pass.md).
inline constexpr std::size_t kPrefetchDistance = 16;

}  // namespace collide::detail
