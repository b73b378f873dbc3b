// repeated_bodies.hpp - whether a movable body is in two of a scene's first
// contacts (private to the library): the first, cheap look of the paths for
// scenes of independent contacts (Schedule::build's one batch, islands()'
// one island per contact). A pile or a chain repeats a body within its
// first two contacts, the debris scene of 2M bodies within 4096 contacts
// with a probability above 0.99; such scenes then cost those paths nothing
// more than this look.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"

namespace collide::detail {

/// Contacts the look covers.
inline constexpr std::size_t kRepeatProbe = 4096;

/// Whether a movable body (inverse mass inv_mass[i * stride] not 0) is in two
/// of the contacts [0, probe), probe <= kRepeatProbe, whose indices are valid:
/// an open-addressing set of their bodies in `set` (resized to 64 KiB; the
/// caller's scratch, kept between calls).
template <class T>
bool movable_body_repeats(const BodyIndex* a, const BodyIndex* b, std::size_t probe, const T* inv_mass,
                          std::size_t stride, std::vector<std::uint32_t>& set) {
  constexpr int kSlotBits = 14;
  constexpr std::size_t kSlots = std::size_t{1} << kSlotBits;
  static_assert(kSlots >= 4 * kRepeatProbe, "the set stays at most half full");
  constexpr BodyIndex kEmpty = std::numeric_limits<BodyIndex>::max();
  set.assign(kSlots, kEmpty);
  const auto insert = [&](BodyIndex i) {
    if (is_immovable(inv_mass[i * stride])) return true;
    // Fibonacci hashing: the top kSlotBits bits of i times 2^64 / golden ratio.
    for (std::size_t s = (std::uint64_t{i} * 0x9E3779B97F4A7C15u) >> (64 - kSlotBits);; s = (s + 1) % kSlots) {
      if (set[s] == i) return false;
      if (set[s] == kEmpty) {
        set[s] = i;
        return true;
      }
    }
  };
  for (std::size_t k = 0; k < probe; ++k) {
    if (!insert(a[k]) || !insert(b[k])) return true;
  }
  return false;
}

}  // namespace collide::detail
