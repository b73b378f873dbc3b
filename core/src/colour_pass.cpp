// colour_pass.cpp - the windowed greedy colouring of colour_pass.hpp.
#include "colour_pass.hpp"

#include <algorithm>
#include <atomic>
#include <bit>

#include "chunks.hpp"
#include "contact_indices.hpp"

namespace collide::detail {
namespace {

constexpr std::size_t kWindow = schedule_windows::kColourWindow;

/// A body's table word: its tag in the top byte and, below, bit c for each
/// colour c < kColours that its earlier contacts of the window hold. The
/// tag says whose the bits are: the window's own tag (1 .. kLastTag, given
/// to the windows a thread colours in turn) makes them the window's; any
/// other tag means none; tag 0 marks an immovable body, which joins no
/// colour and whose word is never written. So a window starts from clean
/// words without a pass to clear them; only when a thread's tags wrap
/// around is its table filled anew.
constexpr unsigned kTagShift = 24;
static_assert(kColours == kTagShift, "the colours fill the bits below the tag");
constexpr std::uint32_t kColourBits = (std::uint32_t{1} << kTagShift) - 1;
constexpr std::uint32_t kImmovableTag = 0;
constexpr std::uint32_t kFreeTag = 0xFF;  // a movable body no window has tagged yet
constexpr std::uint32_t kLastTag = 0xFE;

/// The label of a contact in its window's overflow.
constexpr std::uint8_t kOverflow = kColours;

inline bool movable(std::uint32_t word) { return (word >> kTagShift) != kImmovableTag; }

/// One thread's tables, for the windows it colours.
struct ChunkTables {
  std::uint32_t* mask;                    // body_count words
  std::uint32_t tag = kLastTag;           // the last window's tag
  ScratchVector<std::uint32_t>* levels;   // the overflow's level table, filled on first use
  std::vector<std::uint32_t> overflow;    // the overflow's levels, in input order
  std::vector<std::uint32_t> level_slot;  // its counting sort
  std::vector<std::uint32_t> sorted;
  ColourSummary summary;
};

/// Every movable body's word free, every immovable body's tagged so.
template <class T>
void fill_tags(const InverseMasses<T>& inv_mass, std::size_t bodies, std::uint32_t* mask) {
  for (std::size_t i = 0; i < bodies; ++i) mask[i] = (inv_mass.immovable(i) ? kImmovableTag : kFreeTag) << kTagShift;
}

/// Colours of window [w0, w1), whose tag is `tag`, into label[w0, w1);
/// returns the window's highest colour + 1 (0 for a window of overflow only).
std::uint32_t colour_window(const ContactIndices& c, std::size_t w0, std::size_t w1, std::uint32_t tag,
                            std::uint32_t* __restrict mask, std::uint8_t* __restrict label, std::size_t& conflicts) {
  const BodyIndex* __restrict a = c.a;
  const BodyIndex* __restrict b = c.b;
  const std::size_t ahead = w1 > kPrefetchDistance ? w1 - kPrefetchDistance : 0;
  std::uint32_t used_colours = 0;
  std::size_t met = 0;
  const std::uint32_t tagged = tag << kTagShift;
  for (std::size_t k = w0; k < w1; ++k) {
    if (k < ahead) {
      __builtin_prefetch(mask + a[k + kPrefetchDistance], 1, 3);
      __builtin_prefetch(mask + b[k + kPrefetchDistance], 1, 3);
    }
    const BodyIndex i = a[k];
    const BodyIndex j = b[k];
    const std::uint32_t mi = mask[i];
    const std::uint32_t mj = mask[j];
    const std::uint32_t held_i = (mi >> kTagShift) == tag ? mi & kColourBits : 0;
    const std::uint32_t held_j = (mj >> kTagShift) == tag ? mj & kColourBits : 0;
    met += static_cast<std::size_t>(held_i != 0) + static_cast<std::size_t>(held_j != 0);
    const std::uint32_t free = ~(held_i | held_j) & kColourBits;
    const std::uint32_t colour = free != 0 ? static_cast<std::uint32_t>(std::countr_zero(free)) : kColours;
    label[k] = static_cast<std::uint8_t>(colour);
    const std::uint32_t bit = free & (~free + 1);  // the colour's bit; 0 for the overflow
    used_colours |= bit;
    // Branches, not selects: a select would store the ground's word back
    // and chain every ground contact through it.
    if (movable(mi)) mask[i] = tagged | held_i | bit;
    if (movable(mj)) mask[j] = tagged | held_j | bit;
  }
  conflicts += met;
  return static_cast<std::uint32_t>(std::bit_width(used_colours));
}

/// The window's overflow, labelled kOverflow and placed by the colour sort
/// in order[o0, o1) in input order, regrouped by its own levels; appends the
/// levels' sizes to `batches`.
void schedule_overflow(const ContactIndices& c, std::uint32_t* order, std::size_t o0, std::size_t o1,
                       const std::uint32_t* mask, ChunkTables& t, std::vector<std::uint32_t>& batches) {
  ScratchVector<std::uint32_t>& table = *t.levels;
  if (table.size() != c.body_count) table.assign(c.body_count, 0);  // zero outside a window's use
  const std::size_t m = o1 - o0;
  t.overflow.resize(m);
  std::uint32_t levels = 0;
  for (std::size_t s = 0; s < m; ++s) {
    const std::uint32_t k = order[o0 + s];
    const BodyIndex i = c.a[k];
    const BodyIndex j = c.b[k];
    const bool mi = movable(mask[i]);
    const bool mj = movable(mask[j]);
    const std::uint32_t L = std::max(mi ? table[i] : 0U, mj ? table[j] : 0U);
    t.overflow[s] = L;
    if (mi) table[i] = L + 1;
    if (mj) table[j] = L + 1;
    levels = std::max(levels, L + 1);
  }
  // Stable counting sort of the overflow by level; each level is one batch
  // (levels leave no gap, so none is empty).
  t.level_slot.assign(levels + 1, 0);
  for (std::size_t s = 0; s < m; ++s) ++t.level_slot[t.overflow[s] + 1];
  for (std::uint32_t L = 0; L < levels; ++L) {
    batches.push_back(t.level_slot[L + 1]);
    t.level_slot[L + 1] += t.level_slot[L];
  }
  t.sorted.resize(m);
  for (std::size_t s = 0; s < m; ++s) t.sorted[t.level_slot[t.overflow[s]]++] = order[o0 + s];
  std::copy(t.sorted.begin(), t.sorted.end(), order + o0);
  for (std::size_t s = 0; s < m; ++s) {
    table[c.a[order[o0 + s]]] = 0;
    table[c.b[order[o0 + s]]] = 0;
  }
}

/// Window w: colours, the colour sort into order[w0, w1), the overflow's
/// levels, and the table words cleared. False when an index of the window
/// is bad (nothing was read through it).
template <class T>
bool schedule_window(const ContactIndices& c, const InverseMasses<T>& inv_mass, std::size_t w, ColourScratch& s,
                     ChunkTables& t, std::uint32_t* order) {
  const std::size_t w0 = w * kWindow;
  const std::size_t w1 = std::min(c.count, w0 + kWindow);
  if (!indices_below(c.a + w0, c.b + w0, w1 - w0, index_bound(c.body_count)) &&
      first_bad_contact(c.a, c.b, w0, w1, c.body_count) != w1) {
    return false;
  }
  if (t.tag == kLastTag) {
    fill_tags(inv_mass, c.body_count, t.mask);
    t.tag = 0;
  }
  ++t.tag;
  std::uint8_t* label = s.label.data();
  const std::uint32_t colours = colour_window(c, w0, w1, t.tag, t.mask, label, t.summary.conflicts);
  t.summary.colours = std::max(t.summary.colours, colours);

  // The colour sort: colours 0 .. kColours - 1, then the overflow block.
  std::uint32_t slot[kColours + 1] = {};
  count_levels(label, w0, w1, slot);
  std::vector<std::uint32_t>& batches = s.batches[w];
  batches.clear();
  std::uint32_t start = static_cast<std::uint32_t>(w0);
  for (std::uint32_t& count : slot) {
    if (&count != &slot[kOverflow] && count != 0) batches.push_back(count);
    const std::uint32_t size = count;
    count = start;
    start += size;
  }
  const std::size_t overflow = w1 - slot[kOverflow];
  // Mostly one colour (a scattered scene): runs keep their slot in a register.
  const bool runs = std::size_t{2} * (slot[1] - slot[0]) > w1 - w0;
  scatter_by_level(label, w0, w1, slot, order, runs);
  if (overflow != 0) {
    t.summary.overflow += overflow;
    schedule_overflow(c, order, w1 - overflow, w1, t.mask, t, batches);
  }
  return true;
}

}  // namespace

template <class T>
ColourSummary colour_contacts(const ContactIndices& contacts, const InverseMasses<T>& inv_mass, std::size_t workers,
                              ColourScratch& scratch, std::uint32_t* order, Batches& out) {
  const std::size_t n = contacts.count;
  out.begin.assign(1, 0);
  if (n == 0) {
    describe_batches(order, out);
    return {};
  }
  const std::size_t windows = (n + kWindow - 1) / kWindow;
  const std::size_t chunks = std::max<std::size_t>(1, std::min(workers, windows));
  scratch.masks.resize(chunks);
  scratch.levels.resize(chunks);
  scratch.label.resize(n);
  scratch.batches.resize(windows);
  std::vector<ChunkTables> tables(chunks);
  std::atomic<std::size_t> first_failed{windows};
  for_each_chunk(windows, chunks, [&](std::size_t ch, std::size_t first, std::size_t last) {
    ScratchVector<std::uint32_t>& mask = scratch.masks[ch];
    mask.resize(contacts.body_count);
    ChunkTables& t = tables[ch];  // tag kLastTag: the first window fills the table
    t.mask = mask.data();
    t.levels = &scratch.levels[ch];
    for (std::size_t w = first; w < last && w < first_failed.load(std::memory_order_relaxed); ++w) {
      if (!schedule_window(contacts, inv_mass, w, scratch, t, order)) {
        std::size_t seen = first_failed.load(std::memory_order_relaxed);
        while (w < seen && !first_failed.compare_exchange_weak(seen, w, std::memory_order_relaxed)) {
        }
        break;
      }
    }
  });
  if (const std::size_t w = first_failed.load(); w < windows) {
    throw_first_bad_contact("collide::Schedule::build: ", contacts.a, contacts.b, w * kWindow, n, contacts.body_count);
  }
  ColourSummary summary;
  for (const ChunkTables& t : tables) {
    summary.colours = std::max(summary.colours, t.summary.colours);
    summary.overflow += t.summary.overflow;
    summary.conflicts += t.summary.conflicts;
  }
  std::uint32_t end = 0;
  for (const std::vector<std::uint32_t>& sizes : scratch.batches) {
    for (const std::uint32_t size : sizes) out.begin.push_back(end += size);
  }
  describe_batches(order, out);
  return summary;
}

template ColourSummary colour_contacts<float>(const ContactIndices&, const InverseMasses<float>&, std::size_t,
                                              ColourScratch&, std::uint32_t*, Batches&);
template ColourSummary colour_contacts<double>(const ContactIndices&, const InverseMasses<double>&, std::size_t,
                                               ColourScratch&, std::uint32_t*, Batches&);
template ColourSummary colour_contacts<long double>(const ContactIndices&, const InverseMasses<long double>&,
                                                    std::size_t, ColourScratch&, std::uint32_t*, Batches&);

}  // namespace collide::detail
