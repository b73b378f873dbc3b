// collide/eval/bandwidth.hpp - the machine's memory bandwidth, the denominator of
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
// * Cache sizes: /sys (cpu0's cache directory) first, else
//   sysconf(_SC_LEVEL*_CACHE_SIZE), else CPUID (leaf 0x8000001D on AMD, or
//   the legacy 0x80000005/6 when a hypervisor hides it; leaf 4 on Intel) -
//   CPUID last, because under a hypervisor it may report
//   the host's. A size none of them gives is unknown (std::nullopt), never
//   0: some VMs have no /sys cache directory, and sysconf then answers 0. The sources are injectable (MachineProbe)
//   so that tests can feed an empty /sys and fake sysconf and CPUID.
// * The triad's default array size is max(4 x last-level cache, 128 MiB),
//   capped at 1/32 of physical memory per array (the three arrays together
//   under a tenth of it): a VM that reports a huge L3 (some say 508 MiB
//   through sysconf) must not make the triad allocate gigabytes.
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace collide {

/// Where a cache size came from.
enum class CacheSource { sysfs, sysconf, cpuid, unknown };
const char* to_string(CacheSource source);

/// One cache size: bytes of one instance of the data or unified cache of a
/// level, or nullopt when no source says.
struct CacheSize {
  std::optional<std::size_t> bytes;
  CacheSource source = CacheSource::unknown;
};

/// The sources of the machine facts. system_probe() has the real ones; a
/// test replaces any of them. A function that is empty counts as a source
/// that knows nothing.
struct MachineProbe {
  /// cpu0's cache directory (index0/, index1/, ... with level, type, size).
  std::string sysfs_cache_dir = "/sys/devices/system/cpu/cpu0/cache";
  /// sysconf of the cache size of `level` (1 = L1 data); <= 0 when unknown.
  std::function<long(int level)> sysconf_cache_bytes;
  /// The cache size of `level` as CPUID reports it.
  std::function<std::optional<std::size_t>(int level)> cpuid_cache_bytes;
  /// sysconf(_SC_PHYS_PAGES) * sysconf(_SC_PAGESIZE), or nullopt.
  std::function<std::optional<std::size_t>()> physical_memory_bytes;
};

/// The real sources of the machine the process runs on.
MachineProbe system_probe();

/// The cache size of `level` (1, 2, 3, 4): /sys, else sysconf, else CPUID.
CacheSize cache_size(int level, const MachineProbe& probe = system_probe());

/// Bytes of one instance of the data or unified cache of `level` as cpu0
/// sees it, or nullopt when no source says.
std::optional<std::size_t> cache_bytes(int level);

/// CPUID's cache size of `level` (leaf 0x8000001D on AMD, else 0x80000005/6;
/// leaf 4 on Intel), or nullopt (not x86, another vendor, no such leaf).
std::optional<std::size_t> cpuid_cache_bytes(int level);

/// Size of the last-level data or unified cache in bytes: the highest level
/// known (32 MiB if none is).
std::size_t last_level_cache_bytes(const MachineProbe& probe = system_probe());

/// The triad's default array size: max(4 x last-level cache, 128 MiB),
/// capped at physical memory / 32 when physical memory is known.
std::size_t default_triad_array_bytes(const MachineProbe& probe = system_probe());

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
  /// default_triad_array_bytes().
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
/// default_triad_array_bytes(). Allocates three arrays of that size
/// for the duration of the call.
TriadResult measure_triad(int threads, std::size_t array_bytes = 0, int passes = 10);

/// The same over the caller's arrays, allocating nothing: `passes` timed
/// passes (at least 1) of `triad`, for a caller that reads the bandwidth
/// again and again (collide_bench --timing-check, once a round).
TriadResult measure_triad(TriadArrays& triad, int passes = 10);

}  // namespace collide
