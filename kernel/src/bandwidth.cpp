// bandwidth.cpp - the triad bandwidth and the cache sizes of bandwidth.hpp.
//
// bench/triad.cpp measures the same triad inside Google Benchmark (mean over
// the benchmark's iterations); this is the library's reusable form, which the
// report uses (best pass, see the header). The loop and the slicing are the
// same.
#include "collide/bandwidth.hpp"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

namespace collide {

namespace {

// "32768K" / "2M" / "1048576" -> bytes; 0 if unparsable.
std::size_t parse_size(const std::string& text) {
  std::size_t value = 0, pos = 0;
  while (pos < text.size() && text[pos] >= '0' && text[pos] <= '9') {
    value = value * 10 + static_cast<std::size_t>(text[pos] - '0');
    ++pos;
  }
  if (pos == 0) return 0;
  const char unit = pos < text.size() ? text[pos] : ' ';
  if (unit == 'K' || unit == 'k') value <<= 10;
  if (unit == 'M' || unit == 'm') value <<= 20;
  if (unit == 'G' || unit == 'g') value <<= 30;
  return value;
}

}  // namespace

std::size_t cache_bytes(int level) {
  for (int index = 0; index < 16; ++index) {
    const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(index) + "/";
    std::ifstream level_file(dir + "level"), type_file(dir + "type"), size_file(dir + "size");
    int found_level = 0;
    std::string type, size;
    if (!(level_file >> found_level) || !(type_file >> type) || !(size_file >> size)) continue;
    if (found_level == level && type != "Instruction") return parse_size(size);
  }
  return 0;
}

std::size_t last_level_cache_bytes() {
  for (int level = 4; level >= 1; --level) {
    if (const std::size_t bytes = cache_bytes(level); bytes != 0) return bytes;
  }
  return std::size_t{32} << 20;
}

TriadResult measure_triad(int threads, std::size_t array_bytes, int passes) {
  threads = std::max(1, threads);
  passes = std::max(1, passes);
  if (array_bytes == 0) array_bytes = std::max<std::size_t>(4 * last_level_cache_bytes(), std::size_t{128} << 20);
  const std::size_t n = array_bytes / sizeof(float);
  // new[] without value-initialisation: the first touch below is what maps the
  // pages, on the thread that will use them.
  const std::unique_ptr<float[]> a(new float[n]), b(new float[n]), c(new float[n]);
  oneapi::tbb::task_arena arena(threads);

  // Runs f(begin, end) over [0, n) in `threads` contiguous slices.
  auto for_slices = [&](auto&& f) {
    arena.execute([&] {
      oneapi::tbb::parallel_for(
          oneapi::tbb::blocked_range<std::size_t>(0, n, n / static_cast<std::size_t>(threads) / 16 + 1),
          [&](const oneapi::tbb::blocked_range<std::size_t>& r) { f(r.begin(), r.end()); },
          oneapi::tbb::static_partitioner());
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
      for (std::size_t i = begin; i < end; ++i) pc[i] = pa[i] + s * pb[i];
    });
  };

  triad();  // warm-up: threads started, pages mapped, nothing left to fault
  std::vector<double> seconds;
  for (int p = 0; p < passes; ++p) {
    const auto t0 = std::chrono::steady_clock::now();
    triad();
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  // The result is read so the stores cannot be dropped.
  volatile float sink = c[n / 2];
  (void)sink;

  std::sort(seconds.begin(), seconds.end());
  const double bytes = 12.0 * static_cast<double>(n);
  TriadResult r;
  r.bytes_per_second = bytes / seconds.front();
  r.median_bytes_per_second = bytes / seconds[seconds.size() / 2];
  r.array_bytes = n * sizeof(float);
  r.threads = threads;
  r.passes = passes;
  return r;
}

}  // namespace collide
