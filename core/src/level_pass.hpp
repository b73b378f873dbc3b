// level_pass.hpp - the level of every contact in input order (passes 1 and 2
// of the level schedule, schedule.hpp): contact k goes to the batch one past
// the latest batch of any earlier contact on one of its movable bodies, or
// to its level window's floor if that is higher (private to the library).
//
// Design notes
// ------------
// * The body table (pass 1, streaming over the bodies) holds each body's
//   first free level, or a sentinel for a body with inverse mass 0. Folding
//   "movable" into the table means the level pass reads one random word per
//   body instead of two (the inverse mass and the level), and the inverse
//   masses are read once, in order.
// * The level of contact k depends on every earlier contact, so the pass
//   cannot be split exactly (a chunk's levels are a max-plus function of
//   every body's incoming level, and evaluating it costs a second pass). On
//   scattered bodies (random indices over contacts/2 bodies) it is bound by
//   the latency of the two random table entries, which the indices
//   kPrefetchDistance contacts ahead make predictable: prefetching them
//   keeps enough misses in flight. It counts nothing per level: a histogram
//   increment there is a store-to-load chain whenever neighbours share a
//   level (every contact of a scene of independent pairs).
// * Every index is checked before it is used (contact_indices.hpp): each
//   block of kCheckBlock contacts is screened branch-free, then assigned, so
//   a contact that fails throws before any table word of it is read or
//   written; a branch per contact inside the loop costs more than the
//   blocks.
// * The table and the levels are bytes while the levels fit below the
//   sentinel (fewer than 254 levels: every scene but long chains): a table of
//   1M bodies then fits in L2, and the pass streams a quarter of the bytes.
//   The first contact whose level does not fit stops the narrow pass; its
//   caller copies both arrays into 32-bit words and goes on from there.
// docs/decisions/0015-the-schedules-level-pass.md has the measurements.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "schedule_input.hpp"

namespace collide::detail {

/// The table word of a body that never conflicts (inverse mass 0). No level
/// + 1 equals it: the narrow pass stops before (assign_levels), and a wide
/// level is at most contacts - 1 < 2^32 - 2.
template <class Word>
inline constexpr Word kImmovableWord = std::numeric_limits<Word>::max();

/// Pass 1 for the bodies [begin, end).
template <class Word, class T>
void fill_body_table(const InverseMasses<T>& inv_mass, std::size_t begin, std::size_t end, Word* table) {
  for (std::size_t i = begin; i < end; ++i) table[i] = inv_mass.immovable(i) ? kImmovableWord<Word> : Word{0};
}

/// What the level pass carries from contact to contact, and across the copy
/// to wide words.
struct LevelState {
  std::uint32_t levels = 0;   ///< the highest level so far + 1
  std::size_t conflicts = 0;  ///< dependencies met (Schedule::conflicts)
  std::uint32_t floor = 0;    ///< the current window's floor (schedule.hpp, "Level windows")
};

/// Pass 2 from contact `from` on, over the body table `table` (pass 1's)
/// into `level`. Returns the contact where it stopped: contacts.count, or for
/// a narrow Word the first contact whose level + 1 would not fit below the
/// sentinel, left untouched. Throws std::invalid_argument (contact_indices.hpp)
/// for the first contact with a bad index, before any of its table words is
/// read or written.
template <class Word>
std::size_t assign_levels(const ContactIndices& contacts, std::size_t from, Word* table, Word* level,
                          LevelState& state);

extern template std::size_t assign_levels<std::uint8_t>(const ContactIndices&, std::size_t, std::uint8_t*,
                                                        std::uint8_t*, LevelState&);
extern template std::size_t assign_levels<std::uint32_t>(const ContactIndices&, std::size_t, std::uint32_t*,
                                                         std::uint32_t*, LevelState&);

}  // namespace collide::detail
