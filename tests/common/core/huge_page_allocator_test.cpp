// Tests of the large-table allocator (common/core/huge_page_allocator.h).
#include "common/core/huge_page_allocator.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>
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

// Freed blocks are kept and handed out again for the same mapped size, up
// to kRecycledMaxBytes in all; a vector on a reused block still starts from
// its own values.
TEST(HugePageAllocator, FreedBlocksAreReusedWithinABound) {
  const std::size_t bytes = std::size_t{3} << 20, mapped = 2 * kTwoMiB;
  void* a = huge_page_map(bytes);
  const std::size_t kept = recycled_bytes();  // (earlier tests' blocks)
  ASSERT_LE(kept + mapped, kRecycledMaxBytes);
  std::memset(a, 0x7f, bytes);
  huge_page_unmap(a, bytes);
  EXPECT_EQ(recycled_bytes(), kept + mapped);
  void* b = huge_page_map(bytes);  // the same size: from the kept blocks
  EXPECT_EQ(recycled_bytes(), kept);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(b) % kTwoMiB, 0u);
  huge_page_unmap(b, bytes);
  {
    TableVector<float> v(bytes / sizeof(float), 0.5f);  // possibly on the block just freed
    for (float x : v) ASSERT_EQ(x, 0.5f);
  }
  // Never more than the bound, however much is freed.
  std::vector<void*> blocks;
  for (std::size_t k = 0; k < 2 * kRecycledMaxBytes / mapped; ++k) blocks.push_back(huge_page_map(bytes));
  for (void* p : blocks) huge_page_unmap(p, bytes);
  EXPECT_LE(recycled_bytes(), kRecycledMaxBytes);
  EXPECT_GE(recycled_bytes() + mapped, kRecycledMaxBytes);
}

}  // namespace
}  // namespace skyfarm
