// test_large_allocator.cpp - the memory of large arrays
// (collide/large_allocator.hpp, core/src/large_allocator.cpp).
//
// What this proves
// ----------------
// * allocate_large gives memory aligned as asked below 2 MiB, and aligned to
//   a whole 2 MiB page from 2 MiB on (what the huge-page advice needs), every
//   byte writable; an array whose byte count overflows is refused with
//   std::bad_array_new_length, an impossible size with std::bad_alloc,
//   before anything is allocated.
// * LargeAllocator behaves as std::allocator does for std::vector: values
//   initialised as asked, kept through growth; the owning buffers and the
//   labels that use it keep their contents when they grow past 2 MiB.
// Whether the system grants huge pages is its own (the allocation only
// advises them), so no test asserts it.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <vector>

#include <gtest/gtest.h>

#include "collide/bodies.hpp"
#include "collide/labels.hpp"
#include "collide/large_allocator.hpp"

namespace collide::test {
namespace {

bool aligned_to(const void* p, std::size_t align) { return reinterpret_cast<std::uintptr_t>(p) % align == 0; }

TEST(LargeAllocator, SmallAllocationsAreAlignedAsAsked) {
  for (const std::size_t align :
       {std::size_t{1}, std::size_t{8}, std::size_t{16}, std::size_t{64}, std::size_t{4096}}) {
    for (const std::size_t bytes : {std::size_t{0}, std::size_t{1}, std::size_t{100}, detail::kHugePage - 1}) {
      std::unique_ptr<unsigned char[], detail::FreeLarge> p(
          static_cast<unsigned char*>(detail::allocate_large(bytes, align)));
      ASSERT_NE(p, nullptr);
      EXPECT_TRUE(aligned_to(p.get(), align)) << "align " << align << ", bytes " << bytes;
      if (bytes > 0) std::memset(p.get(), 0xab, bytes);
    }
  }
}

TEST(LargeAllocator, LargeAllocationsStartOnAHugePage) {
  for (const std::size_t bytes : {detail::kHugePage, detail::kHugePage + 1, 5 * detail::kHugePage + 12345}) {
    std::unique_ptr<unsigned char[], detail::FreeLarge> p(
        static_cast<unsigned char*>(detail::allocate_large(bytes, 8)));
    ASSERT_NE(p, nullptr);
    EXPECT_TRUE(aligned_to(p.get(), detail::kHugePage)) << bytes;
    std::memset(p.get(), 0xcd, bytes);
    EXPECT_EQ(p[bytes - 1], 0xcd);
  }
}

TEST(LargeAllocator, OverflowingSizesAreRefused) {
  const std::size_t max = std::numeric_limits<std::size_t>::max();
  EXPECT_THROW((void)detail::allocate_large_array<double>(max / sizeof(double) + 1), std::bad_array_new_length);
  EXPECT_THROW((void)detail::allocate_large(max - 10, 8), std::bad_alloc);
  LargeAllocator<float> a;
  EXPECT_THROW((void)a.allocate(max / 2), std::bad_array_new_length);
}

TEST(LargeAllocator, VectorsKeepTheirValuesAsTheyGrow) {
  std::vector<double, LargeAllocator<double>> v(1000, 1.5);
  for (const double x : v) ASSERT_EQ(x, 1.5);
  v.resize(1'000'000);  // 8 MB: past the huge-page threshold
  EXPECT_EQ(v[999], 1.5);
  EXPECT_EQ(v[1000], 0.0);
  EXPECT_EQ(v.back(), 0.0);
  EXPECT_TRUE(aligned_to(v.data(), detail::kHugePage));
  const std::vector<double, LargeAllocator<double>> copy = v;
  EXPECT_EQ(copy, v);
  // Rebinding (what a container may do with its allocator) keeps the kind.
  const LargeAllocator<std::uint32_t> rebound{LargeAllocator<double>{}};
  EXPECT_TRUE(rebound == LargeAllocator<double>{});
}

TEST(LargeAllocator, BuffersAndLabelsGrowPastAHugePage) {
  BodyBuffer<float> bodies;
  BodyRecord<float> r;
  r.m = 2;
  r.v[1] = 2;
  bodies.push_back(r);
  bodies.resize(1'000'000);  // 4 MB per column
  EXPECT_EQ(bodies.record(0).m, 2.0F);
  EXPECT_EQ(bodies.record(0).v[1], 2.0F);
  EXPECT_EQ(bodies.view().q.w[999'999], 1.0F);  // resize() makes identity-oriented bodies
  Labels labels(3, 7);
  labels.resize(1'000'000);
  EXPECT_EQ(labels[2], 7U);
}

}  // namespace
}  // namespace collide::test
