// collide/labels.hpp - arrays of 32-bit labels, counts and indices that
// their owner fills entirely: the islands' labels (islands.hpp) and the
// schedule's order and levels (schedule.hpp). Growing one leaves its new
// values uninitialised, so that the pass that writes them, often on every
// thread, is the first to touch their pages.
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "collide/large_allocator.hpp"

namespace collide {

/// The allocator of Labels: std::allocator's, except that resize() leaves
/// the new values uninitialised (their owner writes every one, in parallel
/// passes; a std::vector would first zero them on one thread:
/// docs/decisions/0023-fresh-arrays-touched-where-they-are-written.md), on LargeAllocator's memory (huge pages from 2
/// MiB on).
struct LabelAllocator {
  using value_type = std::uint32_t;
  template <class U>
  struct rebind {  // for std::vector<std::uint32_t> only
    static_assert(std::is_same_v<U, std::uint32_t>, "LabelAllocator allocates labels");
    using other = LabelAllocator;
  };

  [[nodiscard]] std::uint32_t* allocate(std::size_t n) { return detail::allocate_large_array<std::uint32_t>(n); }
  void deallocate(std::uint32_t* p, std::size_t) noexcept { detail::free_large(p); }
  /// Value-initialisation (resize(n)) leaves the value as it is.
  void construct(std::uint32_t* p) noexcept { ::new (static_cast<void*>(p)) std::uint32_t; }
  template <class... Args>
  void construct(std::uint32_t* p, Args&&... args) {
    ::new (static_cast<void*>(p)) std::uint32_t(std::forward<Args>(args)...);
  }
  friend bool operator==(const LabelAllocator&, const LabelAllocator&) noexcept { return true; }
  friend bool operator!=(const LabelAllocator&, const LabelAllocator&) noexcept { return false; }
};

/// One label, count or index per contact, body or island.
using Labels = std::vector<std::uint32_t, LabelAllocator>;

}  // namespace collide
