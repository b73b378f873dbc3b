// schedule.cpp - the level schedule of schedule.hpp, built in four passes.
//
// 1. Body table (streaming over bodies): body_next_[i] is the first
//    free batch of body i, 0 to start with, or a sentinel for a body with
//    inverse mass 0. Folding "movable" into the table means the level pass
//    reads one random word per body instead of two (the inverse mass and the
//    batch), and the inverse masses are read once, in order.
// 2. Level pass (sequential, in input order): contact k gets batch
//    max(body_next_[a], body_next_[b]) over its movable bodies, or its
//    window's floor if that is higher (schedule.hpp, "Level windows"), and
//    those bodies' entries become that batch + 1. At each window boundary the
//    levels of the window just done (in L2) are scanned for their span. The level of contact k depends on
//    every earlier contact, so this pass cannot be split exactly (a chunk's
//    levels are a max-plus function of every body's incoming batch, and
//    evaluating it costs a second pass). On scattered bodies (the debris
//    scene: random indices over contacts/2 bodies) it is bound by the latency
//    of the two random body_next_ entries, which the indices kPrefetchDistance
//    contacts ahead make predictable: prefetching them keeps enough misses in
//    flight. It counts nothing per level: a histogram increment there is a
//    store-to-load chain whenever neighbours share a level (every contact on
//    the pairs scene), and cost a fifth of the pass.
//    Every index is checked (< the body count, a != b) before it is used:
//    each block of kCheckBlock contacts is screened branch-free, then
//    assigned, and a contact that fails throws before any body word of it
//    is read or written: a branch per contact inside the loop costs about
//    twice as much as the blocks (docs/decisions/0015).
//    Both arrays hold one byte per body and per contact while the levels fit
//    (fewer than 254 batches: every scene but long chains): the body table of
//    1M bodies then fits in L2, and every pass streams a quarter of the
//    bytes. The first contact whose level does not fit widens both arrays to
//    32-bit words in place, and the pass goes on from that contact.
// 3. Stable counting sort by level (parallel over chunks of contacts): each
//    chunk counts its levels, a prefix over (level, chunk) gives every chunk
//    its first slot in every batch, and each chunk scatters its contacts in
//    input order. The result is the sequential stable sort, whatever the
//    number of chunks; a scene of one level (the pairs scene), or one whose
//    contacts come grouped by level already (a chain in chain order), is
//    the identity and is not sorted.
//    Passes 1 and 3 of a one-level scene stream a few bytes per contact and
//    take a fraction of a millisecond per million: they stay on the calling
//    thread, since waking workers for them cost more wall time than it saved
//    on a loaded machine (measured: the pairs rows).
// 4. Contiguity and the largest batch: O(batches).
//
// One batch, found on every thread. A scene in which no movable body is in
// two contacts (the pairs scene, the contacts of one colour of a broadphase)
// is one batch in input order, and so is its schedule: instead of pass 2 on
// one thread, each thread claims the movable bodies of its chunk of contacts
// in the body table (its chunk's number, 1 to 254), failing at the first body
// it claimed already, and after the join checks that every body of its chunk
// still carries its number: of two chunks that claimed one body, the later
// write stands and the other chunk sees it, in whatever order or interleaving
// the chunks ran. Claims are relaxed atomic bytes; the check decides.
// Any failure (a shared body, a bad index) hands the scene to the passes
// above, which refill the table and name the first bad contact; a scattered
// scene fails within its first few thousand contacts.
//
// The level pass is bound by the random reads of the body table: a prefetch
// 16 contacts ahead hides them (8 leaves misses exposed, 16 to 64 are alike),
// and the table is kept in bytes (docs/decisions/0015-the-schedules-level-pass.md
// has the measurements); the bench rows schedule/<scene>/... time the whole
// build.
#include "collide/schedule.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include <oneapi/tbb/task_arena.h>

#include "chunks.hpp"
#include "repeated_bodies.hpp"

namespace collide {
namespace {

using detail::chunk_count;
using detail::for_each_chunk;

/// The wide body-table sentinel; contact counts stay below it.
constexpr std::uint32_t kImmovable = std::numeric_limits<std::uint32_t>::max();

/// Contacts ahead whose bodies the level pass prefetches. Measured on the
/// debris scene at 2M and 4M contacts: 8 leaves misses exposed, 16 to 64 are
/// within 5% of each other.
constexpr std::size_t kPrefetchDistance = 16;

/// Per-chunk level counts may take at most one 4-byte count per this many
/// contacts (1 B per contact), which keeps a scene of many small batches (a
/// chain) sequential and inside the memory budget of schedule.hpp.
constexpr std::size_t kContactsPerCount = 4;

inline void prefetch_for_write(const void* p) {
#if defined(__GNUC__)
  __builtin_prefetch(p, 1, 3);
#else
  (void)p;
#endif
}

/// The body-table word of a body that never conflicts (inverse mass 0). No
/// level + 1 equals it: a narrow pass stops before (see assign_levels), and a
/// wide level is at most contacts - 1 < 2^32 - 2.
template <class Word>
constexpr Word kImmovableWord = std::numeric_limits<Word>::max();

/// Pass 1 for the bodies [begin, end); body i's inverse mass is
/// inv_mass[i * stride] (1 for SoA views, the record size for packed ones).
template <class Word, class T>
void fill_body_table(const T* inv_mass, std::size_t stride, std::size_t begin, std::size_t end, Word* next) {
  for (std::size_t i = begin; i < end; ++i) {
    next[i] = is_immovable(inv_mass[i * stride]) ? kImmovableWord<Word> : Word{0};
  }
}

/// Throws the std::invalid_argument for the first contact of [k, end) with
/// an index >= body_count or a == b, naming it as validate() does; returns
/// when there is none. Out of line and cold: only a failed check_indices()
/// calls it.
__attribute__((noinline, cold)) void throw_bad_contact(const BodyIndex* a, const BodyIndex* b, std::size_t k,
                                                       std::size_t end, std::size_t body_count) {
  for (; k < end; ++k) {
    if (a[k] < body_count && b[k] < body_count && a[k] != b[k]) continue;
    const std::string at = "[" + std::to_string(k) + "] = ";
    const std::string range = ": out of range (" + std::to_string(body_count) + " bodies)";
    std::string what = "collide::Schedule::build: contacts.";
    const bool a_bad = a[k] >= body_count;
    what.append(a_bad ? "a" : "b").append(at).append(std::to_string(a_bad ? a[k] : b[k]));
    what.append(a_bad || b[k] >= body_count ? range : std::string(": a contact of a body with itself"));
    throw std::invalid_argument(what);
  }
}

/// Contacts the level pass checks at a time (check_indices) before it uses
/// their indices: 2 KiB of indices, still in L1 when the pass reads them
/// (1024 measured slower: 12% over the unchecked build on pairs).
constexpr std::size_t kCheckBlock = 256;

/// The level windows of schedule.hpp: their size is a multiple of
/// kCheckBlock, so that every window starts a block.
constexpr std::size_t kLevelWindow = Schedule::kLevelWindow;
constexpr std::uint32_t kShallowWindowLevels = Schedule::kShallowWindowLevels;
static_assert(kLevelWindow % kCheckBlock == 0);

/// Whether every contact of [0, count) has both indices < bound and a != b.
/// Branch-free, so that it vectorises; with GCC on x86-64 it is also
/// compiled for AVX2 and picked at load time (an ifunc), as validate.cpp's
/// index screen is: SSE2 has no unsigned 32-bit compare or max.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx2", "default")))
#endif
bool indices_below(const BodyIndex* a, const BodyIndex* b, std::size_t count, BodyIndex bound) {
  std::uint32_t bad = 0;
  for (std::size_t c = 0; c < count; ++c) {
    bad |= static_cast<std::uint32_t>(a[c] >= bound) | static_cast<std::uint32_t>(b[c] >= bound) |
           static_cast<std::uint32_t>(a[c] == b[c]);
  }
  return bad == 0;
}

/// The bound indices_below() compares with for `body_count` bodies. With
/// 2^32 or more bodies it is one too strict for index 2^32 - 1, which the
/// exact scan in throw_bad_contact then accepts.
inline BodyIndex index_bound(std::size_t body_count) {
  return static_cast<BodyIndex>(std::min<std::size_t>(body_count, std::numeric_limits<BodyIndex>::max()));
}

/// Throws (throw_bad_contact) unless every contact of [k, end) has both
/// indices < body_count and a != b.
inline void check_indices(const BodyIndex* a, const BodyIndex* b, std::size_t k, std::size_t end,
                          std::size_t body_count) {
  if (__builtin_expect(!indices_below(a + k, b + k, end - k, index_bound(body_count)), 0)) {
    throw_bad_contact(a, b, k, end, body_count);
  }
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

/// Pass 2 from contact k on: the level of each contact from the body table
/// and the window's floor (`window_floor`, carried in and out).
/// Raises `levels` to the number of levels, adds the dependencies met to
/// `conflicts`, and returns the contact where it stopped: n, or for a narrow
/// Word the first contact whose level + 1 would not fit below the sentinel,
/// left untouched. Every block of kCheckBlock contacts is checked
/// (check_indices) before any of its indices is used, so a contact with an
/// index >= body_count or a == b throws before a body word is read or
/// written; the prefetches ahead may name such an index, which is harmless
/// (a prefetch never faults).
template <class Word>
std::size_t assign_levels(const BodyIndex* __restrict a, const BodyIndex* __restrict b, std::size_t k, std::size_t n,
                          std::size_t body_count, Word* __restrict next, Word* __restrict level, std::uint32_t& levels,
                          std::size_t& conflicts, std::uint32_t& window_floor) {
  constexpr Word immovable = kImmovableWord<Word>;
  std::uint32_t count = levels;
  Word floor = static_cast<Word>(window_floor);
  std::size_t met = 0;
  const auto one = [&](std::size_t c) {
    const BodyIndex i = a[c];
    const BodyIndex j = b[c];
    const Word next_i = next[i];
    const Word next_j = next[j];
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
    // ground's word and chains every ground contact through it (measured
    // slower).
    if (movable_i) next[i] = static_cast<Word>(L + 1);
    if (movable_j) next[j] = static_cast<Word>(L + 1);
    count = std::max<std::uint32_t>(count, std::uint32_t{L} + 1);
    return true;
  };
  const auto stop = [&](std::size_t at) {
    levels = count;
    window_floor = floor;
    conflicts += met;
    return at;
  };
  const std::size_t ahead = n > kPrefetchDistance ? n - kPrefetchDistance : 0;
  while (k < n) {
    // Blocks start at multiples of kCheckBlock, also after a narrow pass
    // stopped mid-block, so that every window boundary starts a block.
    const std::size_t end = std::min(n, (k / kCheckBlock + 1) * kCheckBlock);
    if (k % kLevelWindow == 0 && k > 0) {
      const auto [lowest, highest] = level_span(level, k - kLevelWindow, k);
      if (highest - lowest < kShallowWindowLevels) floor = static_cast<Word>(count - 1);
    }
    check_indices(a, b, k, end, body_count);
    // The next block's indices: its check reads them in a burst, which on
    // scattered scenes otherwise waits on memory once per block.
    for (std::size_t p = end; p < std::min(n, end + kCheckBlock); p += 64 / sizeof(BodyIndex)) {
      __builtin_prefetch(a + p, 0, 3);
      __builtin_prefetch(b + p, 0, 3);
    }
    for (const std::size_t prefetched = std::min(end, ahead); k < prefetched; ++k) {
      prefetch_for_write(next + a[k + kPrefetchDistance]);
      prefetch_for_write(next + b[k + kPrefetchDistance]);
      if (!one(k)) return stop(k);
    }
    for (; k < end; ++k) {
      if (!one(k)) return stop(k);
    }
  }
  return stop(n);
}

/// Adds the number of contacts of each level in [begin, end) to count[L].
/// Byte levels are counted in four interleaved tables: one table would make
/// neighbours of the same level (every contact of a pairs scene) wait on each
/// other's store.
template <class Level>
void count_levels(const Level* level, std::size_t begin, std::size_t end, std::uint32_t* count) {
  if constexpr (sizeof(Level) == 1) {
    std::array<std::array<std::uint32_t, 256>, 4> part{};
    std::size_t k = begin;
    for (; k + 4 <= end; k += 4) {
      ++part[0][level[k]];
      ++part[1][level[k + 1]];
      ++part[2][level[k + 2]];
      ++part[3][level[k + 3]];
    }
    for (; k < end; ++k) ++part[0][level[k]];
    for (std::size_t L = 0; L < 256; ++L) {
      const std::uint32_t sum = part[0][L] + part[1][L] + part[2][L] + part[3][L];
      if (sum != 0) count[L] += sum;
    }
  } else {
    for (std::size_t k = begin; k < end; ++k) ++count[level[k]];
  }
}

/// Writes each contact k of [begin, end) to order[next_slot[level[k]]++].
/// With `runs` (a scene whose windows set floors, schedule.hpp: most of a
/// window's contacts share one level), a run of one level keeps its slot in a
/// register: incrementing it in memory for every contact made each store
/// wait on the one before (debris: 19 ms against 16 for the build at 4M).
/// Where neighbours' levels differ (a pile swept cell by cell: 0, 1, 2, 3,
/// 1, 2, ...) the run test mispredicts at every contact, and the plain loop
/// is the faster one (pile: 16 ms against 21).
template <class Level>
void scatter_by_level(const Level* level, std::size_t begin, std::size_t end, std::uint32_t* next_slot,
                      std::uint32_t* order, bool runs) {
  if (!runs) {
    for (std::size_t k = begin; k < end; ++k) order[next_slot[level[k]]++] = static_cast<std::uint32_t>(k);
    return;
  }
  std::size_t k = begin;
  while (k < end) {
    const Level L = level[k];
    std::uint32_t slot = next_slot[L];
    do {
      order[slot++] = static_cast<std::uint32_t>(k++);
    } while (k < end && level[k] == L);
    next_slot[L] = slot;
  }
}

/// The chunks of the one-batch test: each marks its bodies with its number
/// (1 .. 254) in the byte body table, below the immovable sentinel.
constexpr std::size_t kMaxClaimChunks = kImmovableWord<std::uint8_t> - 1;

/// One batch, step 1, for contacts [begin, end) of chunk `id`: claims every
/// movable body in `table` (zeroed), marks immovable ones with the sentinel.
/// False at the first bad index block, body this chunk claimed already, or
/// when another chunk has failed (`failed`, checked once per block).
template <class T>
bool claim_bodies(const BodyIndex* a, const BodyIndex* b, std::size_t begin, std::size_t end, BodyIndex bound,
                  const T* inv_mass, std::size_t stride, std::uint8_t* table, std::uint8_t id,
                  const std::atomic<bool>& failed) {
  constexpr std::uint8_t immovable = kImmovableWord<std::uint8_t>;
  const auto claim = [&](BodyIndex i) {
    std::atomic_ref<std::uint8_t> word(table[i]);
    const std::uint8_t w = word.load(std::memory_order_relaxed);
    if (w == immovable) return true;
    if (w == id) return false;  // a repeat within the chunk
    // Another chunk's number is overwritten: owns_bodies finds the body
    // shared, whichever chunk wrote last, in any order the chunks ran.
    word.store(w == 0 && is_immovable(inv_mass[i * stride]) ? immovable : id, std::memory_order_relaxed);
    return true;
  };
  for (std::size_t k = begin; k < end;) {
    const std::size_t block_end = std::min(end, k + kCheckBlock);
    if (failed.load(std::memory_order_relaxed) || !indices_below(a + k, b + k, block_end - k, bound)) return false;
    for (; k < block_end; ++k) {
      if (!claim(a[k]) || !claim(b[k])) return false;
    }
  }
  return true;
}

/// One batch, step 2, after every chunk has claimed: whether every body of
/// contacts [begin, end) still carries chunk `id`'s number (or is immovable).
inline bool owns_bodies(const BodyIndex* a, const BodyIndex* b, std::size_t begin, std::size_t end, std::uint8_t* table,
                        std::uint8_t id) {
  constexpr std::uint8_t immovable = kImmovableWord<std::uint8_t>;
  bool owned = true;
  for (std::size_t k = begin; k < end; ++k) {
    const std::uint8_t wa = std::atomic_ref<std::uint8_t>(table[a[k]]).load(std::memory_order_relaxed);
    const std::uint8_t wb = std::atomic_ref<std::uint8_t>(table[b[k]]).load(std::memory_order_relaxed);
    owned &= (wa == id || wa == immovable) & (wb == id || wb == immovable);
  }
  return owned;
}

/// Whether the scene is one batch in input order, found on up to `workers`
/// threads (the design notes, "One batch"); if so, `order` is the identity.
/// Needs two chunks at least; `table` holds a byte per body, `scratch` is
/// the probe's (repeated_bodies.hpp).
template <class T>
bool one_batch(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass, std::size_t stride,
               std::size_t workers, std::uint8_t* table, std::uint32_t* order, std::vector<std::uint32_t>& scratch) {
  const std::size_t n = contacts.count;
  const std::size_t chunks = std::min(chunk_count(n, workers), kMaxClaimChunks);
  if (chunks < 2) return false;
  const BodyIndex bound = index_bound(body_count);
  // A first look, on the calling thread, before the body table is touched.
  const std::size_t probe = std::min(n, detail::kRepeatProbe);
  if (!indices_below(contacts.a, contacts.b, probe, bound) ||
      detail::movable_body_repeats(contacts.a, contacts.b, probe, inv_mass, stride, scratch)) {
    return false;
  }
  for_each_chunk(body_count, chunk_count(body_count, workers), [&](std::size_t, std::size_t begin, std::size_t end) {
    std::fill(table + begin, table + end, std::uint8_t{0});
  });
  std::atomic<bool> failed{false};
  for_each_chunk(n, chunks, [&](std::size_t c, std::size_t begin, std::size_t end) {
    const auto id = static_cast<std::uint8_t>(c + 1);
    if (!claim_bodies(contacts.a, contacts.b, begin, end, bound, inv_mass, stride, table, id, failed)) {
      failed.store(true, std::memory_order_relaxed);
    }
  });
  if (failed.load(std::memory_order_relaxed)) return false;
  for_each_chunk(n, chunks, [&](std::size_t c, std::size_t begin, std::size_t end) {
    if (!owns_bodies(contacts.a, contacts.b, begin, end, table, static_cast<std::uint8_t>(c + 1))) {
      failed.store(true, std::memory_order_relaxed);
      return;
    }
    std::iota(order + begin, order + end, static_cast<std::uint32_t>(begin));
  });
  return !failed.load(std::memory_order_relaxed);
}

/// Turns the first `count` bytes of `words` into `count` words, the byte
/// sentinel into the word sentinel.
void widen(Labels& words, std::size_t count) {
  words.resize(count);  // keeps the bytes of the narrow words
  std::uint32_t* const wide = words.data();
  const auto* const narrow = reinterpret_cast<const std::uint8_t*>(wide);
  // Backwards: word i covers bytes 4i..4i+3, which are read already.
  for (std::size_t i = count; i-- > 0;) {
    const std::uint8_t v = narrow[i];
    wide[i] = v == kImmovableWord<std::uint8_t> ? kImmovable : v;
  }
}

}  // namespace

template <class T>
void Schedule::build_strided(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass,
                             std::size_t stride, int threads) {
  // Empty until the build succeeds: a build that throws leaves a schedule of
  // nothing (the buffers keep their capacity), which no solve of a non-empty
  // scene accepts (Solver::solve compares the counts). order_ keeps its size:
  // every entry is rewritten by a build that succeeds, and clearing it made
  // the resize below write the whole array once more (a fifth of the pairs
  // scene's build).
  const auto reset = [this] {
    contact_count_ = 0;
    body_count_ = 0;
    largest_batch_ = 0;
    conflicts_ = 0;
    batch_begin_.clear();
    contiguous_.clear();
  };
  reset();
  if (threads < 0) {
    throw std::invalid_argument("collide::Schedule::build: threads must be >= 0, got " + std::to_string(threads));
  }
  const std::size_t n = contacts.count;
  if (n >= kImmovable) {
    throw std::length_error("collide::Schedule::build: " + std::to_string(n) +
                            " contacts; a schedule holds at most 2^32 - 2");
  }
  if (n > 0 && (contacts.a == nullptr || contacts.b == nullptr)) {
    throw std::invalid_argument("collide::Schedule::build: contacts.a or contacts.b is null but contacts.count = " +
                                std::to_string(n));
  }
  if (body_count > 0 && inv_mass == nullptr) {
    throw std::invalid_argument("collide::Schedule::build: bodies.inv_mass is null but bodies.count = " +
                                std::to_string(body_count));
  }
  const std::size_t workers = threads > 0
                                  ? static_cast<std::size_t>(threads)
                                  : static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  try {
    order_.resize(n);

    // Passes 1 and 2 on one byte per body and per contact while the levels
    // fit in it (every scene of fewer than 254 batches): a quarter of the
    // random lines and of the bytes streamed. The first contact that would
    // need a wider level switches both arrays to words, and the pass goes on
    // from it. The level pass checks every index before it uses it.
    body_next_.resize((body_count + 3) / 4);
    level_.resize((n + 3) / 4);
    auto* const next8 = reinterpret_cast<std::uint8_t*>(body_next_.data());
    if (one_batch(contacts, body_count, inv_mass, stride, workers, next8, order_.data(), slot_)) {
      // What passes 2 to 4 give a scene of one level.
      batch_begin_.assign({std::uint32_t{0}, static_cast<std::uint32_t>(n)});
      contiguous_.assign(1, 1);
      largest_batch_ = n;
      contact_count_ = n;
      body_count_ = body_count;
      return;
    }
    fill_body_table(inv_mass, stride, 0, body_count, next8);
    std::uint32_t levels = 0;
    std::size_t conflicts = 0;
    std::uint32_t window_floor = 0;  // carried across the switch to wide words
    const std::size_t stop =
        assign_levels(contacts.a, contacts.b, 0, n, body_count, next8, reinterpret_cast<std::uint8_t*>(level_.data()),
                      levels, conflicts, window_floor);
    contact_count_ = n;
    if (stop == n) {
      sort_by_level(reinterpret_cast<const std::uint8_t*>(level_.data()), levels, workers, window_floor > 0);
    } else {
      widen(body_next_, body_count);
      widen(level_, n);
      assign_levels(contacts.a, contacts.b, stop, n, body_count, body_next_.data(), level_.data(), levels, conflicts,
                    window_floor);
      sort_by_level(static_cast<const std::uint32_t*>(level_.data()), levels, workers, window_floor > 0);
    }
    body_count_ = body_count;
    conflicts_ = conflicts;
  } catch (...) {
    reset();
    throw;
  }
}

template <class Level>
void Schedule::sort_by_level(const Level* level, std::uint32_t levels, std::size_t workers, bool runs) {
  const std::size_t n = contact_count_;
  std::uint32_t* const order = order_.data();
  batch_begin_.assign(static_cast<std::size_t>(levels) + 1, 0);
  std::size_t chunks = chunk_count(n, workers);
  if (chunks > 1 && chunks * levels > n / kContactsPerCount) chunks = 1;
  if (levels == 1) {
    // One batch: every contact in input order.
    std::iota(order, order + n, std::uint32_t{0});
    batch_begin_[1] = static_cast<std::uint32_t>(n);
  } else if (std::is_sorted(level, level + n)) {
    // Already grouped by level (a chain in chain order, contacts handed over
    // in solve order): the stable sort is the identity, and each batch
    // starts where the levels step up. Levels leave no gap (a contact of
    // level L > 0 follows one of level L - 1 on a body), but a step is
    // filled over any it spans. Unsorted levels stop the test at their
    // first descent.
    // Every batch is consecutive contacts: pass 4 is done here too.
    std::iota(order, order + n, std::uint32_t{0});
    std::size_t largest = 0;
    std::size_t start = 0;
    for (std::size_t k = 1; k < n; ++k) {
      if (level[k] == level[k - 1]) continue;
      largest = std::max(largest, k - start);
      start = k;
      for (std::size_t L = std::size_t{level[k - 1]} + 1; L <= std::size_t{level[k]}; ++L) {
        batch_begin_[L] = static_cast<std::uint32_t>(k);
      }
    }
    batch_begin_[levels] = static_cast<std::uint32_t>(n);
    largest_batch_ = std::max(largest, n - start);
    contiguous_.assign(levels, 1);
    return;
  } else if (chunks == 1) {
    // batch_begin_[L + 1] counts level L, the prefix sum turns counts into
    // starts, and filling advances batch_begin_[L] to the end of level L;
    // shifting by one restores starts.
    count_levels(level, 0, n, batch_begin_.data() + 1);
    for (std::size_t L = 1; L <= levels; ++L) batch_begin_[L] += batch_begin_[L - 1];
    scatter_by_level(level, 0, n, batch_begin_.data(), order, runs);
    for (std::size_t L = levels; L > 0; --L) batch_begin_[L] = batch_begin_[L - 1];
    batch_begin_[0] = 0;
  } else {
    // slot_[c * levels + L]: the count of level L in chunk c, then the slot of
    // chunk c's first contact of level L. Chunk c's contacts of a level follow
    // those of chunks < c, so the order is the sequential stable sort's.
    slot_.assign(chunks * levels, 0);
    std::uint32_t* const slot = slot_.data();
    for_each_chunk(n, chunks, [&](std::size_t c, std::size_t begin, std::size_t end) {
      std::uint32_t* const count = slot + c * levels;
      count_levels(level, begin, end, count);
    });
    std::uint32_t start = 0;
    for (std::size_t L = 0; L < levels; ++L) {
      batch_begin_[L] = start;
      for (std::size_t c = 0; c < chunks; ++c) {
        const std::uint32_t count = slot[c * levels + L];
        slot[c * levels + L] = start;
        start += count;
      }
    }
    batch_begin_[levels] = start;
    for_each_chunk(n, chunks, [&](std::size_t c, std::size_t begin, std::size_t end) {
      std::uint32_t* const next_slot = slot + c * levels;
      scatter_by_level(level, begin, end, next_slot, order, runs);
    });
  }

  // Pass 4: contiguity and the largest batch.
  contiguous_.assign(levels, 0);
  largest_batch_ = 0;
  for (std::size_t L = 0; L < levels; ++L) {
    const std::size_t begin = batch_begin_[L];
    const std::size_t end = batch_begin_[L + 1];
    largest_batch_ = std::max(largest_batch_, end - begin);
    // Ascending and distinct, so consecutive exactly when the span fits.
    contiguous_[L] = static_cast<std::uint8_t>(order[end - 1] - order[begin] == end - begin - 1);
  }
}

std::size_t Schedule::memory_bytes() const {
  return order_.capacity() * sizeof(std::uint32_t) + level_.capacity() * sizeof(std::uint32_t) +
         body_next_.capacity() * sizeof(std::uint32_t) + batch_begin_.capacity() * sizeof(std::uint32_t) +
         contiguous_.capacity() * sizeof(std::uint8_t) + slot_.capacity() * sizeof(std::uint32_t);
}

template void Schedule::build_strided<float>(const ContactView<float>&, std::size_t, const float*, std::size_t, int);
template void Schedule::build_strided<double>(const ContactView<double>&, std::size_t, const double*, std::size_t, int);
template void Schedule::build_strided<long double>(const ContactView<long double>&, std::size_t, const long double*,
                                                   std::size_t, int);

}  // namespace collide
