// large_allocator.cpp - the allocation of collide/large_allocator.hpp:
// malloc below 2 MiB, 2 MiB-aligned memory advised into huge pages above.
#include "collide/large_allocator.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace collide::detail {
namespace {

std::atomic<std::size_t> allocations{0};

}  // namespace

void* allocate_large(std::size_t bytes, std::size_t align) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (bytes < kHugePage) {
    const std::size_t rounded = (std::max<std::size_t>(bytes, 1) + align - 1) / align * align;
    void* p = align <= alignof(std::max_align_t) ? std::malloc(rounded) : std::aligned_alloc(align, rounded);
    if (p == nullptr) throw std::bad_alloc();
    return p;
  }
  if (bytes > static_cast<std::size_t>(-1) - kHugePage) throw std::bad_alloc();
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* p = std::aligned_alloc(kHugePage, rounded);
  if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  (void)::madvise(p, rounded, MADV_HUGEPAGE);  // advice only: failure is harmless
#endif
  return p;
}

void free_large(void* p) noexcept { std::free(p); }

std::size_t large_allocation_count() noexcept { return allocations.load(std::memory_order_relaxed); }

}  // namespace collide::detail
