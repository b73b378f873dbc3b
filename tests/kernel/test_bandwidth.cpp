// test_bandwidth.cpp - collide/bandwidth.hpp: the triad that the bandwidth
// bound of `collide report` and collide_bench is stated against.
//
// What this proves
// ----------------
// * TriadArrays holds array_bytes / 4 floats per array, counts 12 bytes per
//   element and pass, and clamps a thread count below 1 to 1.
// * measure_triad reports what it measured: the best pass is at least the
//   median, both are positive and finite, and it echoes the array size, the
//   threads and the passes it used. (Speeds are not asserted: they belong to
//   the benchmarks.)
// * The cache sizes come from sysfs when the system has it, and the last
//   level is never reported as 0 (32 MiB when unknown).
#include <cmath>
#include <cstddef>

#include <gtest/gtest.h>

#include "collide/bandwidth.hpp"

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

TEST(Bandwidth, CacheSizes) {
  EXPECT_GT(last_level_cache_bytes(), 0u);
  const std::size_t l1 = cache_bytes(1);
  const std::size_t l2 = cache_bytes(2);
  if (l1 != 0 && l2 != 0) {
    EXPECT_LE(l1, l2);
  }
  if (cache_bytes(4) == 0 && cache_bytes(3) != 0) {
    EXPECT_EQ(last_level_cache_bytes(), cache_bytes(3));
  }
}

}  // namespace
}  // namespace collide::test
