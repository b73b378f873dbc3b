// bench/triad.cpp - the machine's memory bandwidth, measured the STREAM way.
//
// Design notes
// ------------
// The triad is the library's (collide::TriadArrays, collide/eval/bandwidth.hpp:
// c[i] = a[i] + s * b[i] over float arrays of at least four times the
// last-level cache each, 12 bytes counted per element as STREAM counts them,
// one contiguous slice per thread, first-touched with the same slicing), the
// same one `collide report` takes its bound from. Here Google Benchmark times
// its passes (the rule of collide/eval/timing.hpp: one more untimed pass,
// then timed ones). The figure is the best pass, not the median: the bound,
// what the memory system can do (STREAM's convention, and how
// collide::measure_triad and the report take it). It is the row's counters
// and is published through set_triad_gbs() for the bw_frac column of every
// later row.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstddef>
#include <string>

#include "collide/eval/bandwidth.hpp"
#include "support.hpp"

namespace collide_bench {

namespace {

void triad_benchmark(benchmark::State& state, int threads) {
  // The library's triad (collide/eval/bandwidth.hpp), the one `collide report`
  // uses; here its passes are timed by the benchmark loop.
  collide::TriadArrays triad(threads, collide::default_triad_array_bytes());
  collide::RunSeries series([&] { triad.pass(); }, [&] { return collide::timed_run([] {}, [&] { triad.pass(); }); });
  for (auto _ : state) state.SetIterationTime(series.next());

  const double best = *std::min_element(series.seconds().begin(), series.seconds().end());
  set_triad_gbs(threads, triad.bytes_per_pass() / best / 1e9);
  Columns columns;
  columns.items = static_cast<double>(triad.elements());
  columns.bytes_per_item = 12;
  columns.seconds = best;
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
