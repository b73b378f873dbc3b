// level_pass.cpp - the level pass of level_pass.hpp.
#include "level_pass.hpp"

#include <algorithm>
#include <utility>

#include "collide/schedule_windows.hpp"
#include "contact_indices.hpp"

namespace collide::detail {
namespace {

/// Contacts checked at a time before their indices are used: 2 KiB of
/// indices, still in L1 when the pass reads them (larger blocks measured
/// slower: docs/decisions/0015-the-schedules-level-pass.md).
constexpr std::size_t kCheckBlock = 256;

/// Every level window starts a check block.
static_assert(schedule_windows::kLevelWindow % kCheckBlock == 0);

inline void prefetch_for_write(const void* p) {
#if defined(__GNUC__)
  __builtin_prefetch(p, 1, 3);
#else
  (void)p;
#endif
}

/// The lowest and highest of level[begin, end), as a loop that vectorises.
template <class Word>
std::pair<std::uint32_t, std::uint32_t> level_span(const Word* level, std::size_t begin, std::size_t end) {
  Word lowest = std::numeric_limits<Word>::max();
  Word highest = 0;
  for (std::size_t k = begin; k < end; ++k) {
    lowest = std::min(lowest, level[k]);
    highest = std::max(highest, level[k]);
  }
  return {lowest, highest};
}

}  // namespace

template <class Word>
std::size_t assign_levels(const ContactIndices& contacts, std::size_t from, Word* __restrict table,
                          Word* __restrict level, LevelState& state) {
  constexpr Word immovable = kImmovableWord<Word>;
  const BodyIndex* __restrict a = contacts.a;
  const BodyIndex* __restrict b = contacts.b;
  const std::size_t n = contacts.count;
  std::uint32_t levels = state.levels;
  Word floor = static_cast<Word>(state.floor);
  std::size_t met = 0;
  // Contact c's level; false (nothing written) when it would not fit a narrow Word.
  const auto one = [&](std::size_t c) {
    const BodyIndex i = a[c];
    const BodyIndex j = b[c];
    const Word next_i = table[i];
    const Word next_j = table[j];
    const bool movable_i = next_i != immovable;
    const bool movable_j = next_j != immovable;
    const Word after_i = movable_i ? next_i : Word{0};
    const Word after_j = movable_j ? next_j : Word{0};
    const Word L = std::max(std::max(after_i, after_j), floor);
    if constexpr (sizeof(Word) < sizeof(std::uint32_t)) {
      if (L == immovable - 1) return false;
    }
    met += static_cast<std::size_t>(after_i > 0) + static_cast<std::size_t>(after_j > 0);
    level[c] = L;
    // Branches, not selects: a select stores the sentinel back into the
    // ground's word and chains every ground contact through it.
    if (movable_i) table[i] = static_cast<Word>(L + 1);
    if (movable_j) table[j] = static_cast<Word>(L + 1);
    levels = std::max<std::uint32_t>(levels, std::uint32_t{L} + 1);
    return true;
  };
  const auto stop = [&](std::size_t at) {
    state.levels = levels;
    state.floor = floor;
    state.conflicts += met;
    return at;
  };
  const std::size_t ahead = n > kPrefetchDistance ? n - kPrefetchDistance : 0;
  std::size_t k = from;
  while (k < n) {
    // Blocks start at multiples of kCheckBlock, also after a narrow pass
    // stopped mid-block, so that every window boundary starts a block.
    const std::size_t end = std::min(n, (k / kCheckBlock + 1) * kCheckBlock);
    if (k % schedule_windows::kLevelWindow == 0 && k > 0) {
      const auto [lowest, highest] = level_span(level, k - schedule_windows::kLevelWindow, k);
      if (highest - lowest < schedule_windows::kShallowWindowLevels) floor = static_cast<Word>(levels - 1);
    }
    check_contact_indices("collide::Schedule::build: ", a, b, k, end, contacts.body_count);
    // The next block's indices: its check reads them in a burst, which on
    // scattered scenes otherwise waits on memory once per block.
    for (std::size_t p = end; p < std::min(n, end + kCheckBlock); p += 64 / sizeof(BodyIndex)) {
      __builtin_prefetch(a + p, 0, 3);
      __builtin_prefetch(b + p, 0, 3);
    }
    for (const std::size_t prefetched = std::min(end, ahead); k < prefetched; ++k) {
      prefetch_for_write(table + a[k + kPrefetchDistance]);
      prefetch_for_write(table + b[k + kPrefetchDistance]);
      if (!one(k)) return stop(k);
    }
    for (; k < end; ++k) {
      if (!one(k)) return stop(k);
    }
  }
  return stop(n);
}

template std::size_t assign_levels<std::uint8_t>(const ContactIndices&, std::size_t, std::uint8_t*, std::uint8_t*,
                                                 LevelState&);
template std::size_t assign_levels<std::uint32_t>(const ContactIndices&, std::size_t, std::uint32_t*, std::uint32_t*,
                                                  LevelState&);

}  // namespace collide::detail
