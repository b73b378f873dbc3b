// first_touch.hpp - the first touch of a solve's new scratch, on the solve's
// threads, before any of its kernels runs (private to the library).
//
// Design notes
// ------------
// * Why: the first write to a page of fresh memory is a page fault (the
//   system zeroes the page and maps it), 4 KiB at a time where transparent
//   huge pages are off or refused, 2 MiB where they are granted
//   (collide/large_allocator.hpp). A one-shot solve (`collide solve`, a
//   Python collide.solve, a Dask task) grows every buffer of a fresh Solver;
//   left to the passes that first write them, those faults fell inside the
//   kernel's time, and made it vary from run to run (most in the colour
//   order, whose copy of the contacts is fresh memory too; the measurements:
//   docs/decisions/0023-fresh-arrays-touched-where-they-are-written.md).
// * What: a Solver first sizes every buffer the solve will use, collecting
//   the bytes that are new in a FirstTouch, and has them touched, one byte
//   per 4 KiB page, by the threads of its arena: the allocate phase,
//   SolveStats::allocate_seconds. A solve whose buffers are already large
//   enough allocates and touches nothing.
// * The split: each part of the static partition touches the same fraction
//   of every buffer, as the copies of prepared_contacts.cpp split their
//   arrays, so that on a machine of several memory nodes a page tends to
//   land on the node of the thread that writes it.
#pragma once

#include <array>
#include <cstddef>

#include <oneapi/tbb/task_arena.h>

#include "scratch_vector.hpp"

namespace collide::detail {

/// Memory to be touched before a solve's kernels run.
class FirstTouch {
 public:
  /// The size of the pages touched: one byte is written in each.
  static constexpr std::size_t kPage = 4096;

  /// Adds bytes [p, p + bytes) (nothing for 0 bytes). Past kMaxSpans spans
  /// the span is touched at once, on the calling thread.
  void add(void* p, std::size_t bytes);
  /// resize_scratch(v, n), adding v's elements when it gave v new storage;
  /// returns whether it did.
  template <class T>
  bool resize(ScratchVector<T>& v, std::size_t n) {
    const bool grew = resize_scratch(v, n);
    if (grew) add(v.data(), n * sizeof(T));
    return grew;
  }

  [[nodiscard]] bool empty() const { return count_ == 0; }

  /// Writes a zero byte in every page of every span, on the threads of
  /// `arena`, and forgets the spans. The bytes are the spans' own (new,
  /// uninitialised elements), so nothing else is changed.
  void run(tbb::task_arena& arena);

 private:
  struct Span {
    unsigned char* p = nullptr;
    std::size_t bytes = 0;
  };
  static constexpr std::size_t kMaxSpans = 64;
  std::array<Span, kMaxSpans> spans_{};
  std::size_t count_ = 0;
};

}  // namespace collide::detail
