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
  // A block just below and just at the threshold round-trip through both paths.
  TableVector<char> below(kHugePageThreshold - 1, 'a'), at(kHugePageThreshold, 'b');
  EXPECT_EQ(below.back(), 'a');
  EXPECT_EQ(at.back(), 'b');
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(at.data()) % kTwoMiB, 0u);
}

}  // namespace
}  // namespace skyfarm
