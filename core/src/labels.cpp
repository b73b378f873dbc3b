// labels.cpp - LabelAllocator (collide/labels.hpp): malloc below 2 MiB,
// 2 MiB-aligned memory advised into huge pages above.
#include "collide/labels.hpp"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace collide {

std::uint32_t* LabelAllocator::allocate(std::size_t n) {
  constexpr std::size_t kHuge = std::size_t{2} << 20;
  if (n > std::numeric_limits<std::size_t>::max() / sizeof(std::uint32_t)) throw std::bad_array_new_length();
  const std::size_t bytes = n * sizeof(std::uint32_t);
  if (bytes < kHuge) {
    void* p = std::malloc(std::max<std::size_t>(bytes, 1));
    if (p == nullptr) throw std::bad_alloc();
    return static_cast<std::uint32_t*>(p);
  }
  const std::size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
  void* p = std::aligned_alloc(kHuge, rounded);
  if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  (void)madvise(p, rounded, MADV_HUGEPAGE);  // advice only: failure is harmless
#endif
  return static_cast<std::uint32_t*>(p);
}

void LabelAllocator::deallocate(std::uint32_t* p, std::size_t) noexcept { std::free(p); }

}  // namespace collide
