// scratch_records.hpp - the solver's packing buffer: uninitialised storage for
// packed records, grown to the largest scene and kept.
//
// A std::vector would zero every record it grows by, and the first touch of
// each 4 KiB page is a page fault: on a scene of millions of bodies the two
// outweighed the kernel itself (the profile:
// docs/decisions/0023-fresh-arrays-touched-where-they-are-written.md). So
// the storage is left uninitialised (pack() writes every record before the
// kernel reads it) and in huge pages (collide/large_allocator.hpp): 2 MiB
// pages fault 512 times less often and cost fewer TLB misses on random
// access. New storage is first
// touched by the solver's allocate phase (first_touch.hpp), on every thread,
// before packing starts.
#pragma once

#include <cstddef>

#include "collide/large_allocator.hpp"
#include "first_touch.hpp"

namespace collide::detail {

template <class Record>
class ScratchRecords {
 public:
  ScratchRecords() = default;
  ScratchRecords(const ScratchRecords&) = delete;
  ScratchRecords& operator=(const ScratchRecords&) = delete;
  ~ScratchRecords() { free_large(data_); }

  /// Storage for n records (contents unspecified); allocates only when n is
  /// more than any n before, and then adds the new storage to `touch`.
  Record* reserve(std::size_t n, FirstTouch& touch) {
    if (n <= capacity_) return data_;
    free_large(data_);  // first: its records are not kept, and the peak is lower
    data_ = nullptr;
    capacity_ = 0;
    data_ = allocate_large_array<Record>(n);
    capacity_ = n;
    touch.add(data_, n * sizeof(Record));
    return data_;
  }

 private:
  Record* data_ = nullptr;
  std::size_t capacity_ = 0;
};

}  // namespace collide::detail
