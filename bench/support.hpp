// bench/support.hpp - what every benchmark of collide_bench shares: the
// byte count of the law, the machine's cache, memory and load facts, the
// triad bandwidth measured earlier in the same run, the timed loop and the
// counter layout.
//
// Design notes
// ------------
// * Bytes per collision is a property of the model, not of the code: the law's
//   inputs and outputs, each counted once, per contact. For the rigid model a
//   contact reads, for each of its two bodies, the inverse mass, the three
//   inverse moments, the quaternion, the position, v and w (17 values) and
//   writes v and w (6 values); it reads its two 4-byte indices, c, n and e (7
//   values, 8 with mu) and writes J (3 values). In float that is
//   2 * 23 * 4 + 2 * 4 + 7 * 4 + 3 * 4 = 232 bytes. A kernel that streams
//   those bytes at the triad's rate is at 100% of the bandwidth bound; a
//   debris scene, whose bodies are shared, may beat 100% because the same body
//   is counted once per contact but fetched from cache the second time.
// * The triad benchmarks run first and publish their bandwidth here (the
//   best pass, the bound as collide report and collide::measure_triad take
//   it), so every later row can report its fraction of the bound measured on
//   the same machine, in the same process, a few seconds earlier.
// * Every row of the table has the same counters (see Columns), so the
//   tabular console output prints one header for the whole run; a column that
//   does not apply to a row is 0: coll/s = collisions per second (contacts
//   scheduled per second on schedule rows, elements per second on triad
//   rows), n over the median iteration time; GB/s = coll/s x B/coll; bw_frac
//   = collide::bandwidth_fraction (collide/eval/timing.hpp): GB/s over the
//   triad's GB/s at the same thread count; B/coll = bytes of the law's inputs and outputs per
//   collision; batches = schedule batches; sched_B/c =
//   Schedule::memory_bytes() / contacts; peak_MiB = VmHWM.
// * Rows time themselves (UseManualTime) by the rule of
//   collide/eval/timing.hpp, the one `collide report` follows: one untimed
//   warm-up run before the loop, then per iteration the untimed work (the
//   scene's reset) and the one timed call with steady_clock around it alone;
//   the row's figure is the median iteration. Google Benchmark decides how
//   many iterations there are (--benchmark_min_time) and its Time column is
//   their mean; the counters (coll/s, GB/s, bw_frac) are from the median,
//   like every figure of the report. Reading the clock costs tens of
//   nanoseconds against at least tens of microseconds for the smallest
//   solve, and unlike PauseTiming/ResumeTiming it does not distort small N.
//   The CPU column of Google Benchmark is the main thread's CPU time over the
//   whole loop, untimed work included: read the counters or the Time column.
#pragma once

#include <benchmark/benchmark.h>

#include <cstddef>
#include <string>

#include "collide/contacts.hpp"
#include "collide/eval/timing.hpp"
#include "collide/eval/traffic.hpp"

namespace collide_bench {

/// Bytes of the rigid law's inputs and outputs for one contact, each counted
/// once (232 for float without friction, 456 for double).
template <class T>
constexpr std::size_t bytes_per_collision(bool friction) {
  return collide::bytes_per_collision(collide::Model::rigid, sizeof(T), friction);
}

/// Size of the last-level cache in bytes: collide::last_level_cache_bytes()
/// (/sys, else sysconf, else CPUID; a hypervisor may report the whole host's
/// L3 through the last two). 32 MiB if unknown.
std::size_t llc_bytes();

/// A field of /proc/self/status ("VmRSS", "VmHWM") in bytes, or 0 if unknown.
double status_bytes(const char* field);

/// The 1-minute load average (/proc/loadavg), -1 if unknown: other processes
/// running skew every row.
double load_average();

/// Resets the peak resident set size (VmHWM) to the current RSS by writing 5
/// to /proc/self/clear_refs. Returns false where the kernel does not allow it.
bool reset_peak_rss();

/// Streams a buffer of the triad's array size (four times the last-level
/// cache, capped by physical memory) through the caches so
/// that none of a scene's lines is left in them, dirty lines included (their
/// write-back happens here rather than inside the next timed solve).
void evict_caches();
/// Bytes of the buffer evict_caches() streams (resident once it first ran).
std::size_t evict_buffer_bytes();

/// Triad bandwidth [GB/s] measured by the triad/t:1 and triad/t:2 rows of this
/// run, 0 until they ran. Index: thread count.
double triad_gbs(int threads);
void set_triad_gbs(int threads, double gbs);

/// Registers triad/t:1 and triad/t:2. Must come before every other row.
void register_triad();

/// The benchmark loop of a row, by the rule of collide/eval/timing.hpp
/// (collide::RunSeries): `untimed()` (nothing by default) and `timed()` once
/// before the loop, the warm-up, not timed; then per iteration `untimed()`
/// and `timed()` with steady_clock around it alone, reported as the
/// iteration's manual time. Returns the median iteration time, the row's
/// figure (Columns::seconds).
template <class Timed, class Untimed = void (*)()>
double time_iterations(
    benchmark::State& state, Timed&& timed, Untimed&& untimed = [] {}) {
  collide::RunSeries series(
      [&] {
        untimed();
        timed();
      },
      [&] { return collide::timed_run(untimed, timed); });
  for (auto _ : state) state.SetIterationTime(series.next());
  return series.median();
}

/// The counters of every row (see the design notes above).
struct Columns {
  double items = 0;           ///< per iteration: collisions, contacts scheduled, triad elements
  double bytes_per_item = 0;  ///< law bytes per collision (12 for the triad)
  double seconds = 0;         ///< one iteration: the median (time_iterations); the triad's best pass
  int threads = 1;            ///< for the bandwidth bound
  double batches = 0;         ///< schedule batches
  double schedule_bytes_per_contact = 0;
};

/// Writes the common counters: coll/s, GB/s, bw_frac, B/coll, batches,
/// sched_B/c, peak_MiB.
void set_counters(benchmark::State& state, const Columns& columns);

}  // namespace collide_bench
