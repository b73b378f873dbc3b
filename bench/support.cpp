// bench/support.cpp - machine facts and counters shared by the benchmarks.
//
// Memory figures come from /proc/self/status, the kernel's own account of the
// process, rather than from an allocator hook: the requirement is on peak
// resident memory, and that includes what TBB, the C++ runtime and page
// granularity add.
#include "support.hpp"

#include "collide/eval/bandwidth.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

namespace collide_bench {

namespace {

double g_triad[3] = {0, 0, 0};

}  // namespace

std::size_t llc_bytes() { return collide::last_level_cache_bytes(); }

double status_bytes(const char* field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  const std::string key = std::string(field) + ":";
  while (std::getline(status, line)) {
    if (line.compare(0, key.size(), key) != 0) {
      continue;
    }
    std::istringstream rest(line.substr(key.size()));
    double kib = 0;
    rest >> kib;
    return kib * 1024.0;
  }
  return 0;
}

double load_average() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  double load = -1;
  if (f) {
    if (std::fscanf(f, "%lf", &load) != 1) {
      load = -1;
    }
    std::fclose(f);
  }
  return load;
}

bool reset_peak_rss() {
  std::ofstream clear_refs("/proc/self/clear_refs");
  clear_refs << "5";
  clear_refs.flush();
  return static_cast<bool>(clear_refs);
}

void evict_caches() {
  // Allocated once and kept: 4x the LLC is enough for any replacement policy
  // to have dropped every earlier line, and reading it costs a few ms, which
  // is not timed.
  static const std::size_t size = evict_buffer_bytes();
  static const std::unique_ptr<std::uint8_t[]> buffer = [] {
    std::unique_ptr<std::uint8_t[]> b(new std::uint8_t[size]);
    std::fill_n(b.get(), size, std::uint8_t{1});
    return b;
  }();
  std::uint64_t sum = 0;
  for (std::size_t i = 0; i < size; i += 64) {
    sum += buffer[i];
  }
  benchmark::DoNotOptimize(sum);
}

// The triad's size: 4 x LLC, capped by physical memory (a VM may report a huge L3).
std::size_t evict_buffer_bytes() { return collide::default_triad_array_bytes(); }

double triad_gbs(int threads) { return threads >= 1 && threads <= 2 ? g_triad[threads] : 0.0; }

void set_triad_gbs(int threads, double gbs) {
  if (threads >= 1 && threads <= 2) {
    g_triad[threads] = gbs;
  }
}

void set_counters(benchmark::State& state, const Columns& c) {
  using benchmark::Counter;
  const double seconds = c.seconds > 0 ? c.seconds : 1e-300;
  const double rate = c.items / seconds;
  // Rates are computed here from the median iteration the row measured
  // itself (support.hpp), so that the file reporter, which gets the same
  // counters, agrees with the console.
  state.counters["coll/s"] = Counter(rate);
  state.counters["GB/s"] = Counter(rate * c.bytes_per_item / 1e9);
  state.counters["bw_frac"] = Counter(collide::bandwidth_fraction(rate, c.bytes_per_item, triad_gbs(c.threads) * 1e9));
  state.counters["B/coll"] = Counter(c.bytes_per_item);
  state.counters["batches"] = Counter(c.batches);
  state.counters["sched_B/c"] = Counter(c.schedule_bytes_per_contact);
  state.counters["peak_MiB"] = Counter(status_bytes("VmHWM") / (1024.0 * 1024.0));
}

}  // namespace collide_bench
