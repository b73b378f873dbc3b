// collide/large_allocator.hpp - memory for large arrays, in 2 MiB pages
// where the system gives them: the owning buffers of bodies.hpp and
// contacts.hpp, the labels of labels.hpp, the solver's scratch, the columns
// of a scene file read into memory and the triad's arrays.
//
// Why: the first touch of a page is a fault, and a fault costs more than
// moving the page's bytes (in a virtual machine, whose host serves the fault
// too, more still: docs/decisions/0034-large-arrays-in-huge-pages.md has the
// measurements). Arrays of millions of contacts or bodies are touched once right
// after they are allocated, so their faults are a large part of that pass.
// Transparent huge pages in "madvise" mode (Debian's default) give 2 MiB
// pages only to memory advised so; the advice is harmless where they are off.
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <cstddef>
#include <new>

namespace collide {
namespace detail {

/// The size of a huge page, and the size from which allocate_large asks for
/// them.
inline constexpr std::size_t kHugePage = std::size_t{2} << 20;

/// `bytes` of uninitialised memory aligned to `align` (a power of two, at
/// most kHugePage); from kHugePage bytes on, aligned to and rounded up to
/// whole huge pages and advised into them. Release it with free_large.
/// Throws std::bad_alloc.
[[nodiscard]] void* allocate_large(std::size_t bytes, std::size_t align);
void free_large(void* p) noexcept;

/// Calls of allocate_large so far in this process, from every thread (what
/// the tests count to show that a reused Solver allocates nothing).
std::size_t large_allocation_count() noexcept;

/// allocate_large for n values of T (std::bad_array_new_length if n *
/// sizeof(T) overflows).
template <class T>
[[nodiscard]] T* allocate_large_array(std::size_t n) {
  if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
  return static_cast<T*>(allocate_large(n * sizeof(T), alignof(T)));
}

/// A deleter for std::unique_ptr of memory from allocate_large.
struct FreeLarge {
  void operator()(void* p) const noexcept { free_large(p); }
};

}  // namespace detail

/// std::allocator's behaviour (values initialised as std::vector asks) on
/// allocate_large's memory.
template <class T>
struct LargeAllocator {
  using value_type = T;
  LargeAllocator() = default;
  /// The same allocator for another type (what a container's rebinding
  /// asks for implicitly).
  template <class U>
  // NOLINTNEXTLINE(google-explicit-constructor, hicpp-explicit-conversions)
  constexpr LargeAllocator(const LargeAllocator<U>&) noexcept {}

  [[nodiscard]] T* allocate(std::size_t n) { return detail::allocate_large_array<T>(n); }
  void deallocate(T* p, std::size_t) noexcept { detail::free_large(p); }

  template <class U>
  friend bool operator==(const LargeAllocator&, const LargeAllocator<U>&) noexcept {
    return true;
  }
  template <class U>
  friend bool operator!=(const LargeAllocator&, const LargeAllocator<U>&) noexcept {
    return false;
  }
};

}  // namespace collide
