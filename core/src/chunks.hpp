// chunks.hpp - work split into a few equal chunks of a range, run in parallel
// in the calling thread's task arena (private to the library): the passes
// of Schedule::build and of islands(), whose results must not depend on the
// number of chunks, only their speed.
#pragma once

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

#include <algorithm>
#include <cstddef>

namespace collide::detail {

/// Fewest contacts (or bodies) per parallel chunk: below that, starting a
/// task costs more than the chunk.
inline constexpr std::size_t kMinChunk = std::size_t{1} << 15;

/// Chunks for `items` items on `threads` threads: at least one, at most one
/// per kMinChunk items.
inline std::size_t chunk_count(std::size_t items, std::size_t threads) {
  return std::max<std::size_t>(1, std::min(threads, items / kMinChunk));
}

/// The first item of chunk c of `chunks` equal slices of [0, items) (the
/// first items % chunks slices one item longer); chunk_begin(chunks) = items.
inline std::size_t chunk_begin(std::size_t items, std::size_t chunks, std::size_t c) {
  return items / chunks * c + std::min(c, items % chunks);
}

/// Runs f(chunk, begin, end) over `chunks` equal slices of [0, items), in
/// parallel in the calling thread's arena when there is more than one.
template <class F>
void for_each_chunk(std::size_t items, std::size_t chunks, const F& f) {
  if (chunks == 1) {
    f(std::size_t{0}, std::size_t{0}, items);
    return;
  }
  tbb::parallel_for(
      std::size_t{0}, chunks,
      [&](std::size_t c) { f(c, chunk_begin(items, chunks, c), chunk_begin(items, chunks, c + 1)); },
      tbb::simple_partitioner());
}

}  // namespace collide::detail
