// ordered_blocks.hpp - the writers' pipeline (private to the library):
// blocks of items filled in parallel, drained in order.
//
// Design notes
// ------------
// * The CSV writers (csv_write.cpp) and the drawn-scene writer
//   (drawn_scene.cpp) format text far faster in parallel than one thread
//   does, but a file is written front to back. A tbb pipeline does both: a
//   serial stage hands out block numbers, a parallel stage fills block b
//   (formats its rows), a serial in-order stage drains it (writes it out), so
//   the output is the same bytes for any thread count.
// * At most `tokens` blocks are in flight, one buffer each, so memory stays
//   a few blocks whatever the item count: block b fills ring[b % tokens],
//   which is free again because the in-order stage has drained block
//   b - tokens before b is admitted. A buffer keeps its capacity from block
//   to block; `fill` is handed it as its last block left it and clears it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include <oneapi/tbb/parallel_pipeline.h>
#include <oneapi/tbb/task_arena.h>

namespace collide::detail {

/// Splits items [0, items) into blocks of `block` items (the last may be
/// shorter) and runs fill(begin, end, buffer) for each block in parallel and
/// drain(const buffer, end) for each block in block order, with a Buffer per
/// block in flight (two per thread of the current arena).
template <class Buffer, class Fill, class Drain>
void ordered_blocks(std::size_t items, std::size_t block, const Fill& fill, const Drain& drain) {
  const std::size_t blocks = (items + block - 1) / block;
  const std::size_t tokens = 2 * static_cast<std::size_t>(std::max(1, oneapi::tbb::this_task_arena::max_concurrency()));
  std::vector<Buffer> ring(tokens);
  std::size_t next = 0;
  oneapi::tbb::parallel_pipeline(
      tokens,
      oneapi::tbb::make_filter<void, std::size_t>(oneapi::tbb::filter_mode::serial_in_order,
                                                  [&](oneapi::tbb::flow_control& fc) -> std::size_t {
                                                    if (next == blocks) {
                                                      fc.stop();
                                                      return 0;
                                                    }
                                                    return next++;
                                                  }) &
          oneapi::tbb::make_filter<std::size_t, std::size_t>(oneapi::tbb::filter_mode::parallel,
                                                             [&](std::size_t b) {
                                                               fill(b * block, std::min(items, (b + 1) * block),
                                                                    ring[b % tokens]);
                                                               return b;
                                                             }) &
          oneapi::tbb::make_filter<std::size_t, void>(oneapi::tbb::filter_mode::serial_in_order, [&](std::size_t b) {
            const Buffer& done = ring[b % tokens];
            drain(done, std::min(items, (b + 1) * block));
          }));
}

}  // namespace collide::detail
