// Tests of the large-table allocator (common/core/huge_page_allocator.h).
#include "common/core/huge_page_allocator.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>

namespace skyfarm {
namespace {

constexpr std::uintptr_t kTwoMiB = std::uintptr_t{2} << 20;

TEST(HugePageAllocator, LargeBlocksStartOnAHugePageAndHoldTheirValues) {
  // 3 MiB of floats: mapped on its own, rounded to 4 MiB, aligned to 2 MiB.
  TableVector<float> v(3u << 18, 0.0f);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kTwoMiB, 0u);
  for (float x : v) ASSERT_EQ(x, 0.0f);
  std::iota(v.begin(), v.end(), 0.0f);
  EXPECT_EQ(v.back(), static_cast<float>(v.size() - 1));
  // Growing moves the values into a new mapping; copies are independent.
  v.resize(v.size() * 2, 1.0f);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kTwoMiB, 0u);
  EXPECT_EQ(v[12345], 12345.0f);
  EXPECT_EQ(v.back(), 1.0f);
  TableVector<float> copy = v;
  copy[0] = -1.0f;
  EXPECT_EQ(v[0], 0.0f);
  EXPECT_EQ(copy[1], 1.0f);
}

TEST(HugePageAllocator, SmallBlocksComeFromTheHeapAlignedForVectors) {
  TableVector<double> small(100, 2.5);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % 64u, 0u);
  EXPECT_EQ(small[99], 2.5);
  // Blocks just below and at each threshold round-trip through every path.
  TableVector<char> heap(kOwnMappingMinBytes - 1, 'a'), own(kOwnMappingMinBytes, 'b'),
      below_huge(kHugePageMinBytes - 1, 'c'), huge(kHugePageMinBytes, 'd');
  EXPECT_EQ(heap.back(), 'a');
  EXPECT_EQ(own.back(), 'b');
  EXPECT_EQ(below_huge.back(), 'c');
  EXPECT_EQ(huge.back(), 'd');
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(huge.data()) % kTwoMiB, 0u);
}

TEST(HugePageAllocator, MemoryIsCountedAsMapped) {
  EXPECT_EQ(mapped_bytes(1000), 1000u);                                   // from the heap
  EXPECT_EQ(mapped_bytes(kOwnMappingMinBytes + 1), kOwnMappingMinBytes + 4096);  // whole pages
  EXPECT_EQ(mapped_bytes(kHugePageMinBytes), kTwoMiB);                    // whole huge pages
  EXPECT_EQ(mapped_bytes((std::size_t{4} << 20) + 1), 3 * kTwoMiB);
  TableVector<float> v(3u << 18);
  EXPECT_EQ(table_memory_bytes(v), 2 * kTwoMiB);
  EXPECT_EQ(table_memory_bytes(TableVector<float>{}), 0u);
}

}  // namespace
}  // namespace skyfarm
