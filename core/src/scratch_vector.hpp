// scratch_vector.hpp - std::vector for scratch that its owner fills entirely
// (private to the library): resize() leaves new elements uninitialised, so
// the pass that writes them, often on every thread, is the first to touch
// their pages (a std::vector would zero them first on one thread).
#pragma once

#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace collide::detail {

/// std::allocator<T>, except that value-initialisation leaves T as it is.
template <class T>
struct UninitialisedAllocator : std::allocator<T> {
  static_assert(std::is_trivial_v<T>, "scratch of trivial values only");
  template <class U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <class U>
  explicit UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  void construct(T* p) noexcept { ::new (static_cast<void*>(p)) T; }
  template <class... Args>
  void construct(T* p, Args&&... args) {
    ::new (static_cast<void*>(p)) T(std::forward<Args>(args)...);
  }
};

template <class T>
using ScratchVector = std::vector<T, UninitialisedAllocator<T>>;

}  // namespace collide::detail
