// batch_sort.cpp - the stable counting sort of batch_sort.hpp.
#include "batch_sort.hpp"

#include <algorithm>
#include <array>
#include <numeric>

#include "chunks.hpp"

namespace collide::detail {
namespace {

/// Per-chunk level counts may take at most one count per this many contacts.
constexpr std::size_t kContactsPerCount = 4;

/// The sort of a scene whose levels never descend: the identity, each batch
/// starting where the levels step up. Levels leave no gap (a contact of level
/// L > 0 follows one of level L - 1 on a body), but a step is filled over any
/// it spans.
template <class Level>
void sorted_levels(const LevelLabels<Level>& labels, std::uint32_t* order, Batches& out) {
  const std::size_t n = labels.count;
  const Level* level = labels.level;
  std::iota(order, order + n, std::uint32_t{0});
  std::size_t largest = 0;
  std::size_t start = 0;
  for (std::size_t k = 1; k < n; ++k) {
    if (level[k] == level[k - 1]) continue;
    largest = std::max(largest, k - start);
    start = k;
    for (std::size_t L = std::size_t{level[k - 1]} + 1; L <= std::size_t{level[k]}; ++L) {
      out.begin[L] = static_cast<std::uint32_t>(k);
    }
  }
  out.begin[labels.levels] = static_cast<std::uint32_t>(n);
  out.largest = std::max(largest, n - start);
  out.contiguous.assign(labels.levels, 1);
}

}  // namespace

template <class Level>
void count_levels(const Level* level, std::size_t begin, std::size_t end, std::uint32_t* count) {
  if constexpr (sizeof(Level) == 1) {
    // Four interleaved tables: one table would make neighbours of the same
    // level (every contact of a pairs scene) wait on each other's store.
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

template <class Level>
void scatter_by_level(const Level* level, std::size_t begin, std::size_t end, std::uint32_t* next_slot,
                      std::uint32_t* order, bool runs) {
  if (!runs) {
    // Where neighbours' levels differ (a pile swept cell by cell: 0, 1, 2,
    // 3, 1, 2, ...) a run test would mispredict at every contact.
    for (std::size_t k = begin; k < end; ++k) order[next_slot[level[k]]++] = static_cast<std::uint32_t>(k);
    return;
  }
  // A run of one level keeps its slot in a register: incrementing it in
  // memory for every contact makes each store wait on the one before.
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

template <class Level>
void sort_by_level(const LevelLabels<Level>& labels, std::size_t workers, bool runs, std::uint32_t* order, Batches& out,
                   std::vector<std::uint32_t>& slot) {
  const std::size_t n = labels.count;
  const std::uint32_t levels = labels.levels;
  const Level* level = labels.level;
  out.begin.assign(static_cast<std::size_t>(levels) + 1, 0);
  if (levels == 1) {
    std::iota(order, order + n, std::uint32_t{0});
    out.begin[1] = static_cast<std::uint32_t>(n);
  } else if (std::is_sorted(level, level + n)) {
    sorted_levels(labels, order, out);
    return;
  } else {
    std::size_t chunks = chunk_count(n, workers);
    if (chunks > 1 && chunks * levels > n / kContactsPerCount) chunks = 1;
    if (chunks == 1) {
      // begin[L + 1] counts level L, the prefix sum turns counts into
      // starts, and filling advances begin[L] to the end of level L;
      // shifting by one restores starts.
      count_levels(level, 0, n, out.begin.data() + 1);
      for (std::size_t L = 1; L <= levels; ++L) out.begin[L] += out.begin[L - 1];
      scatter_by_level(level, 0, n, out.begin.data(), order, runs);
      for (std::size_t L = levels; L > 0; --L) out.begin[L] = out.begin[L - 1];
      out.begin[0] = 0;
    } else {
      // slot[c * levels + L]: the count of level L in chunk c, then the slot
      // of chunk c's first contact of level L. Chunk c's contacts of a level
      // follow those of chunks < c, so the order is the sequential one's.
      slot.assign(chunks * levels, 0);
      for_each_chunk(n, chunks, [&](std::size_t c, std::size_t begin, std::size_t end) {
        count_levels(level, begin, end, slot.data() + c * levels);
      });
      std::uint32_t start = 0;
      for (std::size_t L = 0; L < levels; ++L) {
        out.begin[L] = start;
        for (std::size_t c = 0; c < chunks; ++c) {
          const std::uint32_t count = slot[c * levels + L];
          slot[c * levels + L] = start;
          start += count;
        }
      }
      out.begin[levels] = start;
      for_each_chunk(n, chunks, [&](std::size_t c, std::size_t begin, std::size_t end) {
        scatter_by_level(level, begin, end, slot.data() + c * levels, order, runs);
      });
    }
  }
  describe_batches(order, out);
}

void describe_batches(const std::uint32_t* order, Batches& out) {
  const std::size_t batches = out.count();
  out.contiguous.assign(batches, 0);
  out.largest = 0;
  for (std::size_t L = 0; L < batches; ++L) {
    const std::size_t begin = out.begin[L];
    const std::size_t end = out.begin[L + 1];
    if (end == begin) continue;
    out.largest = std::max(out.largest, end - begin);
    // Ascending and distinct, so consecutive exactly when the span fits.
    out.contiguous[L] = static_cast<std::uint8_t>(order[end - 1] - order[begin] == end - begin - 1);
  }
}

template void sort_by_level<std::uint8_t>(const LevelLabels<std::uint8_t>&, std::size_t, bool, std::uint32_t*, Batches&,
                                          std::vector<std::uint32_t>&);
template void sort_by_level<std::uint32_t>(const LevelLabels<std::uint32_t>&, std::size_t, bool, std::uint32_t*,
                                           Batches&, std::vector<std::uint32_t>&);
template void count_levels<std::uint8_t>(const std::uint8_t*, std::size_t, std::size_t, std::uint32_t*);
template void count_levels<std::uint32_t>(const std::uint32_t*, std::size_t, std::size_t, std::uint32_t*);
template void scatter_by_level<std::uint8_t>(const std::uint8_t*, std::size_t, std::size_t, std::uint32_t*,
                                             std::uint32_t*, bool);
template void scatter_by_level<std::uint32_t>(const std::uint32_t*, std::size_t, std::size_t, std::uint32_t*,
                                              std::uint32_t*, bool);

}  // namespace collide::detail
