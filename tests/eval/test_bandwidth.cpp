// test_bandwidth.cpp - collide/eval/bandwidth.hpp: the triad that the bandwidth
// bound of `collide report` and collide_bench is stated against.
//
// What this proves
// ----------------
// * TriadArrays holds array_bytes / 4 floats per array, counts 12 bytes per
//   element and pass, and clamps a thread count below 1 to 1.
// * measure_triad reports what it measured: the best pass is at least the
//   median, both are positive and finite, and it echoes the array size, the
//   threads and the passes it used; so does its overload over the caller's
//   arrays, which takes fewer than one pass as one. (Speeds are not
//   asserted: they belong to the benchmarks.)
// * Cache sizes: /sys first (a fake cache directory in the build tree), else
//   sysconf, else CPUID (both faked through MachineProbe); a size no source
//   gives is unknown, never 0; the data cache, not the instruction cache.
// * The triad's default arrays stay within memory: a reported L3 of 508 MiB
//   (the sysconf of a virtual machine with 24 GiB) is capped at physical
//   memory / 32 per array.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "collide/eval/bandwidth.hpp"

namespace collide::test {
namespace {

TEST(Bandwidth, TriadArraysSizesAndThreads) {
  TriadArrays triad(0, std::size_t{1} << 20);
  EXPECT_EQ(triad.threads(), 1);
  EXPECT_EQ(triad.elements(), (std::size_t{1} << 20) / sizeof(float));
  EXPECT_EQ(triad.bytes_per_pass(), 12.0 * static_cast<double>(triad.elements()));
  triad.pass();
  TriadArrays two(2, std::size_t{1} << 20);
  EXPECT_EQ(two.threads(), 2);
  two.pass();
}

TEST(Bandwidth, MeasureTriadReportsWhatItMeasured) {
  for (const int threads : {1, 2}) {
    const TriadResult r = measure_triad(threads, std::size_t{4} << 20, 5);
    EXPECT_TRUE(std::isfinite(r.bytes_per_second));
    EXPECT_GT(r.median_bytes_per_second, 0);
    EXPECT_GE(r.bytes_per_second, r.median_bytes_per_second);
    EXPECT_EQ(r.array_bytes, std::size_t{4} << 20);
    EXPECT_EQ(r.threads, threads);
    EXPECT_EQ(r.passes, 5);
  }
}

TEST(Bandwidth, MeasureTriadOverTheCallersArrays) {
  TriadArrays triad(2, std::size_t{4} << 20);
  for (const int passes : {0, 3}) {  // fewer than one pass is taken as one
    const TriadResult r = measure_triad(triad, passes);
    EXPECT_TRUE(std::isfinite(r.bytes_per_second));
    EXPECT_GT(r.median_bytes_per_second, 0);
    EXPECT_GE(r.bytes_per_second, r.median_bytes_per_second);
    EXPECT_EQ(r.array_bytes, std::size_t{4} << 20);
    EXPECT_EQ(r.threads, 2);
    EXPECT_EQ(r.passes, passes < 1 ? 1 : passes);
  }
}

TEST(Bandwidth, CacheSizesOfThisMachine) {
  EXPECT_GT(last_level_cache_bytes(), 0U);
  for (int level = 1; level <= 4; ++level) {
    const CacheSize c = cache_size(level);
    // Known means a positive size and a source; unknown has neither.
    EXPECT_EQ(c.bytes.has_value(), c.source != CacheSource::unknown) << "L" << level;
    if (c.bytes) {
      EXPECT_GT(*c.bytes, 0U) << "L" << level;
    }
    EXPECT_EQ(cache_bytes(level), c.bytes);
  }
  const auto l1 = cache_bytes(1);
  const auto l2 = cache_bytes(2);
  if (l1 && l2) {
    EXPECT_LE(*l1, *l2);
  }
  if (!cache_bytes(4) && cache_bytes(3)) {
    EXPECT_EQ(last_level_cache_bytes(), *cache_bytes(3));
  }
#if defined(__x86_64__)
  // Every x86-64 CPU of AMD or Intel this runs on has CPUID cache leaves.
  const long sc = ::sysconf(_SC_LEVEL1_DCACHE_SIZE);
  const auto id = cpuid_cache_bytes(1);
  std::printf("  L1d: sysconf %ld, cpuid %s; source used: %s\n", sc, id ? std::to_string(*id).c_str() : "none",
              to_string(cache_size(1).source));
  // glibc's sysconf reads the same CPUID leaves on x86: where both answer
  // they agree (this checks the leaf decoding).
  if (sc > 0 && id) {
    EXPECT_EQ(*id, static_cast<std::size_t>(sc));
  }
#endif
}

/// A private cache directory in the form of /sys/devices/system/cpu/cpu0/cache.
class FakeSysfs {
 public:
  explicit FakeSysfs(const std::string& name) : dir_(std::filesystem::path(COLLIDE_TEST_TMP) / name) {
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  ~FakeSysfs() { std::filesystem::remove_all(dir_); }
  FakeSysfs(const FakeSysfs&) = delete;
  FakeSysfs& operator=(const FakeSysfs&) = delete;
  void add(int index, int level, const std::string& type, const std::string& size) const {
    const auto d = dir_ / ("index" + std::to_string(index));
    std::filesystem::create_directories(d);
    std::ofstream(d / "level") << level << "\n";
    std::ofstream(d / "type") << type << "\n";
    std::ofstream(d / "size") << size << "\n";
  }
  [[nodiscard]] std::string path() const { return dir_.string(); }

 private:
  std::filesystem::path dir_;
};

constexpr std::size_t kKiB = 1024, kMiB = std::size_t{1024} * 1024;

/// A probe that knows nothing: no /sys directory, no sysconf, no CPUID.
MachineProbe empty_probe(const FakeSysfs& sysfs) {
  MachineProbe p;
  p.sysfs_cache_dir = sysfs.path();
  return p;
}

TEST(Bandwidth, SysfsComesFirst) {
  FakeSysfs sysfs("sysfs_first");
  sysfs.add(0, 1, "Data", "32K");
  sysfs.add(1, 1, "Instruction", "64K");
  sysfs.add(2, 2, "Unified", "512K");
  MachineProbe p = empty_probe(sysfs);
  p.sysconf_cache_bytes = [](int level) -> long { return level == 3 ? long{16 * kMiB} : long{999}; };
  p.cpuid_cache_bytes = [](int) -> std::optional<std::size_t> { return std::size_t{777}; };
  const CacheSize l1 = cache_size(1, p);
  EXPECT_EQ(l1.bytes, 32 * kKiB);  // the data cache, not the instruction cache
  EXPECT_EQ(l1.source, CacheSource::sysfs);
  EXPECT_EQ(cache_size(2, p).bytes, 512 * kKiB);
  const CacheSize l3 = cache_size(3, p);  // not in /sys: sysconf
  EXPECT_EQ(l3.bytes, 16 * kMiB);
  EXPECT_EQ(l3.source, CacheSource::sysconf);
}

TEST(Bandwidth, EmptySysfsFallsBackToSysconfThenCpuid) {
  FakeSysfs sysfs("empty_sysfs");
  MachineProbe p = empty_probe(sysfs);
  // sysconf knows L1 and L2 (0 and -1 mean "does not know", as glibc says).
  p.sysconf_cache_bytes = [](int level) -> long {
    return level == 1 ? long{48 * kKiB} : level == 2 ? long{kMiB} : level == 3 ? 0L : -1L;
  };
  p.cpuid_cache_bytes = [](int level) -> std::optional<std::size_t> {
    if (level == 3) return 32 * kMiB;
    if (level == 1) return 1;  // never consulted: sysconf knew
    return std::nullopt;
  };
  EXPECT_EQ(cache_size(1, p).bytes, 48 * kKiB);
  EXPECT_EQ(cache_size(1, p).source, CacheSource::sysconf);
  EXPECT_EQ(cache_size(2, p).bytes, kMiB);
  const CacheSize l3 = cache_size(3, p);
  EXPECT_EQ(l3.bytes, 32 * kMiB);
  EXPECT_EQ(l3.source, CacheSource::cpuid);
  const CacheSize l4 = cache_size(4, p);
  EXPECT_FALSE(l4.bytes.has_value());
  EXPECT_EQ(l4.source, CacheSource::unknown);
  EXPECT_EQ(last_level_cache_bytes(p), 32 * kMiB);
}

TEST(Bandwidth, NothingKnownIsUnknownNotZero) {
  FakeSysfs sysfs("nothing_known");
  sysfs.add(0, 1, "Data", "garbage");  // unparsable: not a size of 0
  MachineProbe p = empty_probe(sysfs);
  p.sysconf_cache_bytes = [](int) -> long { return 0; };
  p.cpuid_cache_bytes = [](int) -> std::optional<std::size_t> { return std::nullopt; };
  for (int level = 1; level <= 4; ++level) {
    const CacheSize c = cache_size(level, p);
    EXPECT_FALSE(c.bytes.has_value()) << "L" << level;
    EXPECT_EQ(c.source, CacheSource::unknown);
  }
  EXPECT_STREQ(to_string(CacheSource::unknown), "unknown");
  EXPECT_EQ(last_level_cache_bytes(p), 32 * kMiB);  // the documented default when unknown
}

TEST(Bandwidth, TriadArraysStayWithinMemory) {
  FakeSysfs sysfs("triad_memory");
  MachineProbe p = empty_probe(sysfs);
  // A virtual machine whose sysconf says L3 = 508 MiB, with 24 GiB.
  p.sysconf_cache_bytes = [](int level) -> long { return level == 3 ? long{508 * kMiB} : -1L; };
  p.physical_memory_bytes = []() -> std::optional<std::size_t> { return std::size_t{24} << 30; };
  EXPECT_EQ(default_triad_array_bytes(p), (std::size_t{24} << 30) / 32);  // not 4 x 508 MiB
  // A small machine: the cap wins over the 128 MiB floor too.
  p.physical_memory_bytes = []() -> std::optional<std::size_t> { return std::size_t{1} << 30; };
  EXPECT_EQ(default_triad_array_bytes(p), 32 * kMiB);
  // Memory unknown: no cap.
  p.physical_memory_bytes = nullptr;
  EXPECT_EQ(default_triad_array_bytes(p), std::size_t{4} * 508 * kMiB);
  // A real L3 on a big machine: 4 x L3, above the 128 MiB floor.
  p.sysconf_cache_bytes = [](int level) -> long { return level == 3 ? long{64 * kMiB} : -1L; };
  p.physical_memory_bytes = []() -> std::optional<std::size_t> { return std::size_t{256} << 30; };
  EXPECT_EQ(default_triad_array_bytes(p), 256 * kMiB);
  // The machine the test runs on, whatever it reports: three arrays under a
  // tenth of memory.
  const auto memory = system_probe().physical_memory_bytes();
  ASSERT_TRUE(memory.has_value());
  EXPECT_LE(3 * default_triad_array_bytes(), *memory / 10);
}

}  // namespace
}  // namespace collide::test
