// scratch_vector.hpp - std::vector for scratch that its owner fills entirely
// (private to the library): resize() leaves new elements uninitialised, so
// the pass that writes them, often on every thread, is the first to touch
// their pages (a std::vector would zero them first on one thread), and the
// memory comes from allocate_large (collide/large_allocator.hpp): from 2 MiB
// on, in huge pages where the system grants them, 512 times fewer faults
// than in 4 KiB pages.
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "collide/large_allocator.hpp"

namespace collide::detail {

/// LargeAllocator<T>, except that value-initialisation leaves T as it is.
template <class T>
struct UninitialisedAllocator {
  static_assert(std::is_trivial_v<T>, "scratch of trivial values only");
  using value_type = T;
  template <class U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <class U>
  explicit UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}

  [[nodiscard]] T* allocate(std::size_t n) { return allocate_large_array<T>(n); }
  void deallocate(T* p, std::size_t) noexcept { free_large(p); }
  void construct(T* p) noexcept { ::new (static_cast<void*>(p)) T; }
  template <class... Args>
  void construct(T* p, Args&&... args) {
    ::new (static_cast<void*>(p)) T(std::forward<Args>(args)...);
  }

  template <class U>
  friend bool operator==(const UninitialisedAllocator&, const UninitialisedAllocator<U>&) noexcept {
    return true;
  }
  template <class U>
  friend bool operator!=(const UninitialisedAllocator&, const UninitialisedAllocator<U>&) noexcept {
    return false;
  }
};

template <class T>
using ScratchVector = std::vector<T, UninitialisedAllocator<T>>;

/// Sets v's size to n for a pass that rewrites every element. When n exceeds
/// its capacity, the storage is replaced by room for exactly n (the old
/// values are not copied; the new ones are uninitialised and their pages
/// untouched) and true is returned; otherwise nothing is allocated, the
/// values up to the capacity are those the storage held, and false is
/// returned. So a solver's scratch, sized only this way, has every page up
/// to its capacity touched once its first solve of that size has touched the
/// new storage (first_touch.hpp).
template <class T>
bool resize_scratch(ScratchVector<T>& v, std::size_t n) {
  if (n <= v.capacity()) {
    v.resize(n);  // within the capacity: no allocation, no value written
    return false;
  }
  ScratchVector<T>().swap(v);  // the old storage freed first: no copy, a lower peak
  v.reserve(n);
  v.resize(n);
  return true;
}

}  // namespace collide::detail
