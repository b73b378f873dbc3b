// collide/bandwidth.hpp - the machine's memory bandwidth, the denominator of
// the bandwidth bound (traffic.hpp has the numerator).
//
// Design notes
// ------------
// * The bound is stated against a STREAM-like triad, c[i] = a[i] + s * b[i]
//   over float arrays, counted as STREAM counts it: 12 bytes per element (two
//   loads, one store; the write-allocate read of c is not counted). The
//   arrays are at least four times the last-level cache each, so every pass
//   comes from DRAM whatever the replacement policy.
// * Threads: a task_arena of the requested size and a static partitioner, so
//   each thread owns one contiguous slice; the arrays are first touched with
//   the same slicing (harmless on one NUMA node, right on several).
// * Several timed passes follow one untimed warm-up pass. The bound is the
//   best pass (STREAM's convention: what the memory system can do, which
//   another process on a shared machine can only lower); the median is kept
//   too, to show how noisy the machine was.
// * Cache sizes come from sysfs (cpu0), not from cpuid: under a hypervisor
//   cpuid may report the whole host's L3.
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <cstddef>
#include <memory>

namespace collide {

/// Size in bytes of one instance of the data or unified cache of `level`
/// (1, 2, 3) as cpu0 sees it, or 0 when the system does not say.
std::size_t cache_bytes(int level);

/// Size of the last-level data or unified cache in bytes (32 MiB if unknown).
std::size_t last_level_cache_bytes();

/// One triad measurement.
struct TriadResult {
  double bytes_per_second = 0;         ///< best timed pass, 12 bytes per element: the bound
  double median_bytes_per_second = 0;  ///< median timed pass
  std::size_t array_bytes = 0;         ///< bytes of each of the three arrays
  int threads = 1;
  int passes = 0;  ///< timed passes
};

/// The triad's three arrays and its threads, for a caller that times the
/// passes itself (collide_bench does, inside Google Benchmark); measure_triad
/// below is built on it. Construction allocates the arrays, first-touches
/// them with the threads' slicing and runs one untimed warm-up pass.
class TriadArrays {
 public:
  /// `threads` >= 1 (smaller is taken as 1); `array_bytes` 0 means
  /// max(4 x last-level cache, 128 MiB).
  explicit TriadArrays(int threads, std::size_t array_bytes = 0);
  ~TriadArrays();
  TriadArrays(const TriadArrays&) = delete;
  TriadArrays& operator=(const TriadArrays&) = delete;

  /// One pass of c[i] = a[i] + s * b[i] over every element.
  void pass();
  /// Elements per array.
  [[nodiscard]] std::size_t elements() const;
  /// Bytes one pass counts: 12 per element.
  [[nodiscard]] double bytes_per_pass() const { return 12.0 * static_cast<double>(elements()); }
  [[nodiscard]] int threads() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Measures the triad with `threads` threads (>= 1). `array_bytes` 0 means
/// max(4 x last-level cache, 128 MiB). Allocates three arrays of that size
/// for the duration of the call.
TriadResult measure_triad(int threads, std::size_t array_bytes = 0, int passes = 10);

}  // namespace collide
