// screen_chunks.hpp - a yes/no test over [0, count) in parallel chunks
// (private to the library): the screens of validate.cpp, of the binary
// scene loader and of to_body_buffer.
#pragma once

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_reduce.h>

#include <cstddef>

namespace collide::detail {

/// True when f(begin, end) is true for every chunk of [0, count): on the
/// calling thread for small counts, else in parallel (TBB's arena of the
/// calling thread), since at a million elements a screen is bound by one
/// core's memory bandwidth.
template <class F>
bool screen_chunks(std::size_t count, const F& f) {
  constexpr std::size_t kGrain = std::size_t{1} << 15;
  if (count < 2 * kGrain) return f(std::size_t{0}, count);
  return oneapi::tbb::parallel_reduce(
      oneapi::tbb::blocked_range<std::size_t>(0, count, kGrain), true,
      [&](const oneapi::tbb::blocked_range<std::size_t>& r, bool ok) { return ok && f(r.begin(), r.end()); },
      [](bool x, bool y) { return x && y; });
}

}  // namespace collide::detail
