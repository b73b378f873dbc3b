// bandwidth.cpp - the triad bandwidth and the cache sizes of bandwidth.hpp.
//
// The triad itself lives here once (TriadArrays): `collide report` takes the
// best of its passes (measure_triad), bench/triad.cpp times its passes inside
// Google Benchmark (mean over the iterations).
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

struct TriadArrays::Impl {
  int threads;
  std::size_t n;
  // new[] without value-initialisation: the first touch in the constructor is
  // what maps the pages, on the thread that will use them.
  std::unique_ptr<float[]> a, b, c;
  oneapi::tbb::task_arena arena;

  Impl(int t, std::size_t count)
      : threads(t), n(count), a(new float[count]), b(new float[count]), c(new float[count]), arena(t) {}

  // Runs f(begin, end) over [0, n) in `threads` contiguous slices.
  template <class F>
  void for_slices(F&& f) {
    arena.execute([&] {
      oneapi::tbb::parallel_for(
          oneapi::tbb::blocked_range<std::size_t>(0, n, n / static_cast<std::size_t>(threads) / 16 + 1),
          [&](const oneapi::tbb::blocked_range<std::size_t>& r) { f(r.begin(), r.end()); },
          oneapi::tbb::static_partitioner());
    });
  }
};

TriadArrays::TriadArrays(int threads, std::size_t array_bytes) {
  threads = std::max(1, threads);
  if (array_bytes == 0) array_bytes = std::max<std::size_t>(4 * last_level_cache_bytes(), std::size_t{128} << 20);
  impl_ = std::make_unique<Impl>(threads, array_bytes / sizeof(float));
  impl_->for_slices([&](std::size_t begin, std::size_t end) {
    std::fill(impl_->a.get() + begin, impl_->a.get() + end, 1.0f);
    std::fill(impl_->b.get() + begin, impl_->b.get() + end, 2.0f);
    std::fill(impl_->c.get() + begin, impl_->c.get() + end, 0.0f);
  });
  pass();  // warm-up: threads started, pages mapped, nothing left to fault
}

TriadArrays::~TriadArrays() = default;

void TriadArrays::pass() {
  const float s = 3.0f;
  Impl& m = *impl_;
  m.for_slices([&](std::size_t begin, std::size_t end) {
    const float* __restrict pa = m.a.get();
    const float* __restrict pb = m.b.get();
    float* __restrict pc = m.c.get();
    for (std::size_t i = begin; i < end; ++i) pc[i] = pa[i] + s * pb[i];
  });
}

std::size_t TriadArrays::elements() const { return impl_->n; }
int TriadArrays::threads() const { return impl_->threads; }

TriadResult measure_triad(int threads, std::size_t array_bytes, int passes) {
  passes = std::max(1, passes);
  TriadArrays triad(threads, array_bytes);
  std::vector<double> seconds;
  for (int p = 0; p < passes; ++p) {
    const auto t0 = std::chrono::steady_clock::now();
    triad.pass();
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(seconds.begin(), seconds.end());
  TriadResult r;
  r.bytes_per_second = triad.bytes_per_pass() / seconds.front();
  r.median_bytes_per_second = triad.bytes_per_pass() / seconds[seconds.size() / 2];
  r.array_bytes = triad.elements() * sizeof(float);
  r.threads = triad.threads();
  r.passes = passes;
  return r;
}

}  // namespace collide
