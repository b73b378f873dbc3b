// bandwidth.cpp - the triad bandwidth and the cache sizes of bandwidth.hpp
// (sources and order are stated there).
//
// The triad itself lives here once (TriadArrays): `collide report` takes the
// best of its passes (measure_triad), bench/triad.cpp times its passes inside
// Google Benchmark (mean over the iterations).
#include "collide/eval/bandwidth.hpp"

#include <unistd.h>

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include "collide/large_allocator.hpp"

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

const char* to_string(CacheSource source) {
  switch (source) {
    case CacheSource::sysfs:
      return "sysfs";
    case CacheSource::sysconf:
      return "sysconf";
    case CacheSource::cpuid:
      return "cpuid";
    case CacheSource::unknown:
      break;
  }
  return "unknown";
}

std::optional<std::size_t> cpuid_cache_bytes(int level) {
#if defined(__x86_64__) || defined(__i386__)
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  if (__get_cpuid(0, &eax, &ebx, &ecx, &edx) == 0) return std::nullopt;
  const unsigned max_leaf = eax;
  char vendor[13] = {};
  std::memcpy(vendor, &ebx, 4);
  std::memcpy(vendor + 4, &edx, 4);
  std::memcpy(vendor + 8, &ecx, 4);
  unsigned leaf = 0;
  if (std::strcmp(vendor, "AuthenticAMD") == 0 || std::strcmp(vendor, "HygonGenuine") == 0) {
    // 0x8000001D needs the topology extensions (0x80000001 ECX bit 22);
    // hypervisors often hide them (many VMs do), and then the
    // legacy leaves say: 0x80000005 ECX[31:24] L1d KiB, 0x80000006
    // ECX[31:16] L2 KiB and EDX[31:18] L3 in 512 KiB units.
    if (__get_cpuid(0x80000000U, &eax, &ebx, &ecx, &edx) == 0) return std::nullopt;
    const unsigned max_ext = eax;
    const bool topoext =
        max_ext >= 0x8000001DU && __get_cpuid(0x80000001U, &eax, &ebx, &ecx, &edx) != 0 && (ecx & (1U << 22)) != 0;
    if (!topoext) {
      std::size_t bytes = 0;
      if (level == 1 && max_ext >= 0x80000005U && __get_cpuid(0x80000005U, &eax, &ebx, &ecx, &edx) != 0) {
        bytes = std::size_t{ecx >> 24} << 10;
      } else if ((level == 2 || level == 3) && max_ext >= 0x80000006U &&
                 __get_cpuid(0x80000006U, &eax, &ebx, &ecx, &edx) != 0) {
        bytes = level == 2 ? std::size_t{ecx >> 16} << 10 : std::size_t{edx >> 18} << 19;
      }
      if (bytes == 0) return std::nullopt;
      return bytes;
    }
    leaf = 0x8000001DU;
  } else if (std::strcmp(vendor, "GenuineIntel") == 0) {
    if (max_leaf < 4) return std::nullopt;
    leaf = 4;
  } else {
    return std::nullopt;
  }
  // Both leaves: EAX[4:0] type (0 none, 1 data, 2 instruction, 3 unified),
  // EAX[7:5] level; size = ways x partitions x line x sets, each field + 1.
  for (unsigned sub = 0; sub < 16; ++sub) {
    __cpuid_count(leaf, sub, eax, ebx, ecx, edx);
    const unsigned type = eax & 0x1FU;
    if (type == 0) break;
    if (static_cast<int>((eax >> 5) & 0x7U) != level || type == 2) continue;
    const std::size_t ways = ((ebx >> 22) & 0x3FFU) + 1;
    const std::size_t partitions = ((ebx >> 12) & 0x3FFU) + 1;
    const std::size_t line = (ebx & 0xFFFU) + 1;
    const std::size_t sets = std::size_t{ecx} + 1;
    return ways * partitions * line * sets;
  }
#else
  (void)level;
#endif
  return std::nullopt;
}

MachineProbe system_probe() {
  MachineProbe p;
  p.sysconf_cache_bytes = [](int level) -> long {
    switch (level) {
      case 1:
        return ::sysconf(_SC_LEVEL1_DCACHE_SIZE);
      case 2:
        return ::sysconf(_SC_LEVEL2_CACHE_SIZE);
      case 3:
        return ::sysconf(_SC_LEVEL3_CACHE_SIZE);
      case 4:
        return ::sysconf(_SC_LEVEL4_CACHE_SIZE);
      default:
        return -1;
    }
  };
  p.cpuid_cache_bytes = cpuid_cache_bytes;
  p.physical_memory_bytes = []() -> std::optional<std::size_t> {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long page = ::sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0) return std::nullopt;
    return static_cast<std::size_t>(pages) * static_cast<std::size_t>(page);
  };
  return p;
}

CacheSize cache_size(int level, const MachineProbe& probe) {
  for (int index = 0; index < 16; ++index) {
    const std::string dir = probe.sysfs_cache_dir + "/index" + std::to_string(index) + "/";
    std::ifstream level_file(dir + "level"), type_file(dir + "type"), size_file(dir + "size");
    int found_level = 0;
    std::string type, size;
    if (!(level_file >> found_level) || !(type_file >> type) || !(size_file >> size)) continue;
    if (found_level == level && type != "Instruction") {
      if (const std::size_t bytes = parse_size(size); bytes != 0) return {bytes, CacheSource::sysfs};
    }
  }
  if (probe.sysconf_cache_bytes) {
    if (const long bytes = probe.sysconf_cache_bytes(level); bytes > 0) {
      return {static_cast<std::size_t>(bytes), CacheSource::sysconf};
    }
  }
  if (probe.cpuid_cache_bytes) {
    if (const auto bytes = probe.cpuid_cache_bytes(level); bytes && *bytes != 0) return {bytes, CacheSource::cpuid};
  }
  return {};
}

std::optional<std::size_t> cache_bytes(int level) { return cache_size(level).bytes; }

std::size_t last_level_cache_bytes(const MachineProbe& probe) {
  for (int level = 4; level >= 1; --level) {
    if (const CacheSize c = cache_size(level, probe); c.bytes) return *c.bytes;
  }
  return std::size_t{32} << 20;
}

std::size_t default_triad_array_bytes(const MachineProbe& probe) {
  std::size_t bytes = std::max<std::size_t>(4 * last_level_cache_bytes(probe), std::size_t{128} << 20);
  if (probe.physical_memory_bytes) {
    if (const auto memory = probe.physical_memory_bytes(); memory && *memory > 0) {
      bytes = std::min(bytes, *memory / 32);
    }
  }
  return bytes;
}

struct TriadArrays::Impl {
  int threads;
  std::size_t n;
  // Uninitialised, in huge pages (collide/large_allocator.hpp): the first touch in
  // the constructor is what maps the pages, on the thread that will use them,
  // and in 4 KiB pages its faults took longer than the passes measured.
  std::unique_ptr<float[], detail::FreeLarge> a, b, c;
  oneapi::tbb::task_arena arena;

  Impl(int t, std::size_t count)
      : threads(t),
        n(count),
        a(detail::allocate_large_array<float>(count)),
        b(detail::allocate_large_array<float>(count)),
        c(detail::allocate_large_array<float>(count)),
        arena(t) {}

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
  if (array_bytes == 0) array_bytes = default_triad_array_bytes();
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
  TriadArrays triad(threads, array_bytes);
  return measure_triad(triad, passes);
}

TriadResult measure_triad(TriadArrays& triad, int passes) {
  passes = std::max(1, passes);
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
