// scratch_records.hpp - the solver's packing buffer: uninitialised storage for
// packed records, grown to the largest scene and kept.
//
// A std::vector would zero every record it grows by, and the first touch of
// each 4 KiB page is a page fault: packing 2M rigid bodies (256 MiB) into a
// fresh vector spent more time in memset and faults than in the kernel
// (perf, `collide solve` on 2M debris). So the storage is left
// uninitialised (pack() writes every record before the kernel reads it) and,
// on Linux, advised to transparent huge pages: 2 MiB pages fault 512 times
// less often and cost fewer TLB misses on random access.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace collide::detail {

template <class Record>
class ScratchRecords {
 public:
  ScratchRecords() = default;
  ScratchRecords(const ScratchRecords&) = delete;
  ScratchRecords& operator=(const ScratchRecords&) = delete;
  ~ScratchRecords() { std::free(data_); }

  /// Storage for n records (contents unspecified); allocates only when n is
  /// more than any n before.
  Record* reserve(std::size_t n) {
    if (n <= capacity_) return data_;
    constexpr std::size_t kHuge = std::size_t{2} << 20;
    const std::size_t bytes = n * sizeof(Record);
    const std::size_t align = bytes >= kHuge ? kHuge : alignof(Record);
    const std::size_t rounded = (bytes + align - 1) / align * align;
    void* p = std::aligned_alloc(align, rounded);
    if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (align == kHuge) (void)madvise(p, rounded, MADV_HUGEPAGE);  // advice only: failure is harmless
#endif
    std::free(data_);
    data_ = static_cast<Record*>(p);
    capacity_ = n;
    return data_;
  }

 private:
  Record* data_ = nullptr;
  std::size_t capacity_ = 0;
};

}  // namespace collide::detail
