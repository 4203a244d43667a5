// The SKYVOL1 file (common/assets/volume_file.h): a round trip keeps every
// bit, and every way a file can be malformed is refused with a sentence.
#include "common/assets/volume_file.h"

#include <cmath>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

namespace skyfarm::assets {
namespace {

VolumeGrid small_grid() {
  VolumeGrid g;
  g.size = {3, 2, 4};
  g.voxel_size_m = {12.5, 20.0, 7.25};
  g.origin_m = {-100.0, 3.5, 1e4};
  for (int i = 0; i < 24; ++i) g.values.push_back(0.125f * static_cast<float>(i));
  g.max_value = 0.125f * 23;
  return g;
}

TEST(VolumeFile, RoundTripKeepsEveryBit) {
  const VolumeGrid g = small_grid();
  const std::string bytes = encode_volume_file(g);
  ASSERT_EQ(bytes.size(), kVolumeFileHeaderBytes + 4 * 24);
  EXPECT_TRUE(is_volume_file(bytes));
  VolumeGrid back;
  std::string error;
  ASSERT_TRUE(decode_volume_file(bytes, {}, &back, &error)) << error;
  EXPECT_EQ(back.size, g.size);
  EXPECT_EQ(back.voxel_size_m, g.voxel_size_m);
  EXPECT_EQ(back.origin_m, g.origin_m);
  EXPECT_EQ(back.values, g.values);
  EXPECT_EQ(back.max_value, g.max_value);
  EXPECT_EQ(back.at(2, 1, 3), g.values[2 + 3 * (1 + 2 * 3)]);
  EXPECT_EQ(encode_volume_file(back), bytes);
}

std::string refusal(const std::string& bytes, const VolumeLimits& limits = {}) {
  VolumeGrid g;
  std::string error;
  EXPECT_FALSE(decode_volume_file(bytes, limits, &g, &error));
  return error;
}

template <class T>
void poke(std::string& bytes, std::size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof value);
}

TEST(VolumeFile, RejectsCorruptFiles) {
  const std::string good = encode_volume_file(small_grid());
  EXPECT_NE(refusal("").find("not a skyfarm volume file"), std::string::npos);
  EXPECT_NE(refusal("SKYMESH1" + good.substr(8)).find("bad magic"), std::string::npos);
  EXPECT_NE(refusal(good.substr(0, 40)).find("truncated"), std::string::npos);
  EXPECT_NE(refusal(good.substr(0, good.size() - 1)).find("size does not match"), std::string::npos);
  EXPECT_NE(refusal(good + "x").find("size does not match"), std::string::npos);

  std::string zero = good;
  poke<std::uint32_t>(zero, 12, 0);
  EXPECT_NE(refusal(zero).find("no voxels"), std::string::npos);
  std::string huge = good;
  poke<std::uint32_t>(huge, 8, 0x10000u);
  poke<std::uint32_t>(huge, 12, 0x10000u);
  poke<std::uint32_t>(huge, 16, 0x10000u);
  EXPECT_NE(refusal(huge).find("more than the limit"), std::string::npos);
  poke<std::uint32_t>(huge, 8, 0xffffffffu);
  EXPECT_NE(refusal(huge).find("along an axis"), std::string::npos);
  VolumeLimits tight;
  tight.max_voxels = 23;
  EXPECT_NE(refusal(good, tight).find("more than the limit of 23"), std::string::npos);
  tight = {};
  tight.max_bytes = 95;
  EXPECT_NE(refusal(good, tight).find("bytes, more than the limit"), std::string::npos);

  std::string voxel = good;
  poke<double>(voxel, 28, 0.0);
  EXPECT_NE(refusal(voxel).find("voxel size"), std::string::npos);
  poke<double>(voxel, 28, std::numeric_limits<double>::quiet_NaN());
  EXPECT_NE(refusal(voxel).find("voxel size"), std::string::npos);
  std::string origin = good;
  poke<double>(origin, 60, std::numeric_limits<double>::infinity());
  EXPECT_NE(refusal(origin).find("origin"), std::string::npos);
  std::string negative = good;
  poke<float>(negative, kVolumeFileHeaderBytes + 8, -1.0f);
  EXPECT_NE(refusal(negative).find("voxel value"), std::string::npos);
  std::string nan = good;
  poke<float>(nan, kVolumeFileHeaderBytes + 4 * 23, std::numeric_limits<float>::quiet_NaN());
  EXPECT_NE(refusal(nan).find("voxel value"), std::string::npos);
}

}  // namespace
}  // namespace skyfarm::assets
