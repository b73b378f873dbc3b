// one_batch.cpp - the claim protocol of one_batch.hpp.
#include "one_batch.hpp"

#include <algorithm>
#include <atomic>
#include <numeric>

#include "chunks.hpp"
#include "contact_indices.hpp"
#include "level_pass.hpp"
#include "repeated_bodies.hpp"

namespace collide::detail {
namespace {

constexpr std::uint8_t kImmovable = kImmovableWord<std::uint8_t>;

/// Chunks at most: each marks its bodies with its number, 1 .. 254, below
/// the immovable sentinel.
constexpr std::size_t kMaxClaimChunks = kImmovable - 1;

/// Contacts whose indices are screened at a time before they are used.
constexpr std::size_t kScreenBlock = 256;

/// Step 1, for contacts [begin, end) of chunk `id`: claims every movable
/// body in `table` (zeroed), marks immovable ones with the sentinel. False at
/// the first bad index block, at a body this chunk claimed already, or when
/// another chunk has failed (`failed`, checked once per block).
template <class T>
bool claim_bodies(const ContactIndices& c, std::size_t begin, std::size_t end, const InverseMasses<T>& inv_mass,
                  std::uint8_t* table, std::uint8_t id, const std::atomic<bool>& failed) {
  const BodyIndex bound = index_bound(c.body_count);
  const auto claim = [&](BodyIndex i) {
    std::atomic_ref<std::uint8_t> word(table[i]);
    const std::uint8_t w = word.load(std::memory_order_relaxed);
    if (w == kImmovable) return true;
    if (w == id) return false;  // a repeat within the chunk
    // Another chunk's number is overwritten: owns_bodies finds the body
    // shared, whichever chunk wrote last, in any order the chunks ran.
    word.store(w == 0 && inv_mass.immovable(i) ? kImmovable : id, std::memory_order_relaxed);
    return true;
  };
  for (std::size_t k = begin; k < end;) {
    const std::size_t block_end = std::min(end, k + kScreenBlock);
    if (failed.load(std::memory_order_relaxed) || !indices_below(c.a + k, c.b + k, block_end - k, bound)) {
      return false;
    }
    for (; k < block_end; ++k) {
      if (!claim(c.a[k]) || !claim(c.b[k])) return false;
    }
  }
  return true;
}

/// Step 2, after every chunk has claimed: whether every body of contacts
/// [begin, end) still carries chunk `id`'s number (or is immovable).
bool owns_bodies(const ContactIndices& c, std::size_t begin, std::size_t end, std::uint8_t* table, std::uint8_t id) {
  bool owned = true;
  for (std::size_t k = begin; k < end; ++k) {
    const std::uint8_t wa = std::atomic_ref<std::uint8_t>(table[c.a[k]]).load(std::memory_order_relaxed);
    const std::uint8_t wb = std::atomic_ref<std::uint8_t>(table[c.b[k]]).load(std::memory_order_relaxed);
    owned &= (wa == id || wa == kImmovable) & (wb == id || wb == kImmovable);
  }
  return owned;
}

}  // namespace

template <class T>
bool one_batch(const ContactIndices& contacts, const InverseMasses<T>& inv_mass, std::size_t workers,
               std::uint8_t* table, std::uint32_t* order, std::vector<std::uint32_t>& probe_set) {
  const std::size_t n = contacts.count;
  if (n == 0) return false;
  const std::size_t chunks = std::min(chunk_count(n, workers), kMaxClaimChunks);
  // A first look, on the calling thread, before the body table is touched
  // on every thread; a scene of one chunk goes straight to its one claim
  // pass, which stops at the first repeat as the look would.
  if (chunks > 1) {
    const std::size_t probe = std::min(n, kRepeatProbe);
    if (!indices_below(contacts.a, contacts.b, probe, index_bound(contacts.body_count)) ||
        movable_body_repeats(contacts.a, contacts.b, probe, inv_mass.data, inv_mass.stride, probe_set)) {
      return false;
    }
  }
  const std::size_t bodies = contacts.body_count;
  for_each_chunk(bodies, chunk_count(bodies, workers), [&](std::size_t, std::size_t begin, std::size_t end) {
    std::fill(table + begin, table + end, std::uint8_t{0});
  });
  std::atomic<bool> failed{false};
  for_each_chunk(n, chunks, [&](std::size_t c, std::size_t begin, std::size_t end) {
    if (!claim_bodies(contacts, begin, end, inv_mass, table, static_cast<std::uint8_t>(c + 1), failed)) {
      failed.store(true, std::memory_order_relaxed);
    }
  });
  if (failed.load(std::memory_order_relaxed)) return false;
  for_each_chunk(n, chunks, [&](std::size_t c, std::size_t begin, std::size_t end) {
    if (!owns_bodies(contacts, begin, end, table, static_cast<std::uint8_t>(c + 1))) {
      failed.store(true, std::memory_order_relaxed);
      return;
    }
    std::iota(order + begin, order + end, static_cast<std::uint32_t>(begin));
  });
  return !failed.load(std::memory_order_relaxed);
}

template bool one_batch<float>(const ContactIndices&, const InverseMasses<float>&, std::size_t, std::uint8_t*,
                               std::uint32_t*, std::vector<std::uint32_t>&);
template bool one_batch<double>(const ContactIndices&, const InverseMasses<double>&, std::size_t, std::uint8_t*,
                                std::uint32_t*, std::vector<std::uint32_t>&);
template bool one_batch<long double>(const ContactIndices&, const InverseMasses<long double>&, std::size_t,
                                     std::uint8_t*, std::uint32_t*, std::vector<std::uint32_t>&);

}  // namespace collide::detail
