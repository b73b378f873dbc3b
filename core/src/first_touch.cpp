// first_touch.cpp - the parallel touch of first_touch.hpp.
#include "first_touch.hpp"

#include <algorithm>
#include <cstdint>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

namespace collide::detail {
namespace {

/// Parts of the largest span a task takes at least: 64 pages, 256 KiB.
constexpr std::size_t kPagesPerTask = 64;

std::uintptr_t page_of(const unsigned char* p) {
  return reinterpret_cast<std::uintptr_t>(p) / FirstTouch::kPage * FirstTouch::kPage;
}

/// Pages [p, p + bytes) reaches (bytes > 0).
std::size_t pages(const unsigned char* p, std::size_t bytes) {
  return (page_of(p + bytes - 1) - page_of(p)) / FirstTouch::kPage + 1;
}

/// A zero byte in pages [first, last) of [p, p + bytes): at p itself in the
/// first page, at the page's start in the others, so every byte written is
/// one of the span's.
void touch(unsigned char* p, std::size_t first, std::size_t last) {
  // volatile: the bytes are overwritten later by other code, and the stores
  // must not be optimised away.
  volatile unsigned char* const base = p;
  const std::uintptr_t start = page_of(p);
  for (std::size_t k = first; k < last; ++k) {
    const std::uintptr_t at = k == 0 ? reinterpret_cast<std::uintptr_t>(p) : start + k * FirstTouch::kPage;
    base[at - reinterpret_cast<std::uintptr_t>(p)] = 0;
  }
}

}  // namespace

void FirstTouch::add(void* p, std::size_t bytes) {
  if (bytes == 0) return;
  auto* const bytes_at = static_cast<unsigned char*>(p);
  if (count_ == kMaxSpans) {
    touch(bytes_at, 0, pages(bytes_at, bytes));
    return;
  }
  spans_[count_++] = Span{bytes_at, bytes};
}

void FirstTouch::run(tbb::task_arena& arena) {
  if (count_ == 0) return;
  std::size_t parts = 0;  // the pages of the largest span
  for (std::size_t s = 0; s < count_; ++s) parts = std::max(parts, pages(spans_[s].p, spans_[s].bytes));
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, parts, kPagesPerTask),
        [&](const tbb::blocked_range<std::size_t>& r) {
          // Parts [begin, end) of `parts` are the same fraction of every span.
          for (std::size_t s = 0; s < count_; ++s) {
            const std::size_t n = pages(spans_[s].p, spans_[s].bytes);
            touch(spans_[s].p, r.begin() * n / parts, r.end() * n / parts);
          }
        },
        tbb::static_partitioner());
  });
  count_ = 0;
}

}  // namespace collide::detail
