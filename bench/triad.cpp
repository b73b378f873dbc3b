// bench/triad.cpp - the machine's memory bandwidth, measured the STREAM way.
//
// Design notes
// ------------
// c[i] = a[i] + s * b[i] over float arrays of at least four times the
// last-level cache each (128 MiB here), so that every pass comes from DRAM.
// Bytes are counted as STREAM counts them, 12 per element (two loads, one
// store; the write-allocate read of c is not counted). The stores are plain
// stores, like the kernel's, so the bound compares like with like.
//
// Threads: a tbb::task_arena of 1 or 2 slots and a static partitioner, so each
// thread owns one contiguous slice of the arrays. The arrays are first touched
// with the same partitioning (harmless on one NUMA node, right on several).
// The result is published through set_triad_gbs() for the bw_frac column of
// every later row.
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <memory>
#include <string>

#include "support.hpp"

namespace collide_bench {

namespace {

void triad_benchmark(benchmark::State& state, int threads) {
  const std::size_t array_bytes = std::max<std::size_t>(4 * llc_bytes(), std::size_t{128} << 20);
  const std::size_t n = array_bytes / sizeof(float);
  std::unique_ptr<float[]> a(new float[n]), b(new float[n]), c(new float[n]);
  tbb::task_arena arena(threads);

  // Runs f(begin, end) over [0, n) in `threads` contiguous slices.
  auto for_slices = [&](auto&& f) {
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, n, n / static_cast<std::size_t>(threads) / 16 + 1),
          [&](const tbb::blocked_range<std::size_t>& r) { f(r.begin(), r.end()); }, tbb::static_partitioner());
    });
  };
  for_slices([&](std::size_t begin, std::size_t end) {
    std::fill(a.get() + begin, a.get() + end, 1.0f);
    std::fill(b.get() + begin, b.get() + end, 2.0f);
    std::fill(c.get() + begin, c.get() + end, 0.0f);
  });
  const float s = 3.0f;
  auto triad = [&] {
    for_slices([&](std::size_t begin, std::size_t end) {
      const float* __restrict pa = a.get();
      const float* __restrict pb = b.get();
      float* __restrict pc = c.get();
      for (std::size_t i = begin; i < end; ++i) {
        pc[i] = pa[i] + s * pb[i];
      }
    });
    benchmark::ClobberMemory();
  };

  triad();  // warm-up: threads started, pages mapped
  double seconds = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    triad();
    const auto t1 = Clock::now();
    state.SetIterationTime(seconds_between(t0, t1));
    seconds += seconds_between(t0, t1);
  }
  benchmark::DoNotOptimize(c[n / 2]);

  const double gbs = 12.0 * static_cast<double>(n) * static_cast<double>(state.iterations()) / seconds / 1e9;
  set_triad_gbs(threads, gbs);
  Columns columns;
  columns.items = static_cast<double>(n);
  columns.bytes_per_item = 12;
  columns.seconds = seconds;
  columns.threads = threads;
  set_counters(state, columns);
}

}  // namespace

void register_triad() {
  for (int threads : {1, 2}) {
    benchmark::RegisterBenchmark(("triad/t:" + std::to_string(threads)).c_str(),
                                 [threads](benchmark::State& state) { triad_benchmark(state, threads); })
        ->UseManualTime()
        ->Unit(benchmark::kMicrosecond);
  }
}

}  // namespace collide_bench
