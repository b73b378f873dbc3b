// batch_sort.hpp - contacts grouped into batches by a label per contact
// (their level), stably, on threads (private to the library): passes 3 and
// 4 of the level schedule (schedule.hpp), and the last step of every
// schedule: the contiguity of each batch and the largest one.
//
// Design notes
// ------------
// * A stable counting sort over chunks of contacts: each chunk counts its
//   levels, a prefix over (level, chunk) gives every chunk its first slot in
//   every batch, and each chunk scatters its contacts in input order. The
//   result is the sequential stable sort, whatever the number of chunks.
// * A scene of one level, or one whose contacts come grouped by level
//   already (a chain in chain order, contacts handed over in solve order),
//   is the identity and is not sorted.
// * Per-chunk counts may take at most one 4-byte count per kContactsPerCount
//   contacts, which keeps a scene of many small batches (a chain) sequential
//   and inside the memory budget of schedule.hpp.
// * One-level scenes stay on the calling thread: their pass is too short for
//   waking workers to pay on a loaded machine
//   (docs/decisions/0019-contacts-in-level-order-are-not-sorted.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace collide::detail {

/// The batches of a schedule, over its order (Schedule::solve_order()).
struct Batches {
  std::vector<std::uint32_t> begin;      ///< batch k is order[begin[k], begin[k + 1])
  std::vector<std::uint8_t> contiguous;  ///< 1 where batch k holds consecutive contacts
  std::size_t largest = 0;               ///< contacts in the largest batch

  [[nodiscard]] std::size_t count() const { return begin.empty() ? 0 : begin.size() - 1; }
};

/// A label per contact: level[k] < levels for k < count.
template <class Level>
struct LevelLabels {
  const Level* level = nullptr;
  std::size_t count = 0;
  std::uint32_t levels = 0;
};

/// Groups the contacts into order (stable: input order within a level) and
/// fills `out`, on at most `workers` chunks. `runs`: most neighbours share
/// a level (the level windows set floors), so a run of one level keeps its
/// slot in a register. `slot` is the chunks' scratch, kept between calls.
template <class Level>
void sort_by_level(const LevelLabels<Level>& labels, std::size_t workers, bool runs, std::uint32_t* order, Batches& out,
                   std::vector<std::uint32_t>& slot);

extern template void sort_by_level<std::uint8_t>(const LevelLabels<std::uint8_t>&, std::size_t, bool, std::uint32_t*,
                                                 Batches&, std::vector<std::uint32_t>&);
extern template void sort_by_level<std::uint32_t>(const LevelLabels<std::uint32_t>&, std::size_t, bool, std::uint32_t*,
                                                  Batches&, std::vector<std::uint32_t>&);

/// Pass 4: out.contiguous and out.largest from out.begin and the order.
void describe_batches(const std::uint32_t* order, Batches& out);

/// Adds the number of contacts of each level in [begin, end) to count[L].
template <class Level>
void count_levels(const Level* level, std::size_t begin, std::size_t end, std::uint32_t* count);

/// Writes each contact k of [begin, end) to order[next_slot[level[k]]++]
/// (`runs` as for sort_by_level).
template <class Level>
void scatter_by_level(const Level* level, std::size_t begin, std::size_t end, std::uint32_t* next_slot,
                      std::uint32_t* order, bool runs);

}  // namespace collide::detail
