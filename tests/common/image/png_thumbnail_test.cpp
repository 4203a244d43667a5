// The PNG thumbnail (common/image/png_thumbnail.h): its size, and each pixel
// the mean of its source block in linear light, checked against the sRGB
// curve's own numbers (IEC 61966-2-1): black and white average to linear
// 0.5, which encodes as 0.7354 (code 188), not to the code mean 128.
#include "common/image/png_thumbnail.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <vector>

#include "common/image/png_writer.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("skyfarm_thumb_" + name + "_" + std::to_string(::getpid()) + ".png");
}

TEST(PngThumbnail, BlocksAverageInLinearLight) {
  // 4 x 2: left half a black/white checker, right half grey code 100 with one code 200.
  const std::vector<std::uint8_t> rgb = {
      0,   0,   0,   255, 255, 255, 100, 100, 100, 200, 200, 200,  // row 0
      255, 255, 255, 0,   0,   0,   100, 100, 100, 100, 100, 100,  // row 1
  };
  const fs::path source = temp_file("source"), thumb = temp_file("thumb");
  write_png_rgb8(source, 4, 2, rgb, {{"skyfarm:request", "{}"}});
  write_png_thumbnail(source, thumb, 2);
  const PngFile t = read_png(thumb);
  ASSERT_EQ(t.width, 2);
  ASSERT_EQ(t.height, 1);
  EXPECT_EQ(t.bit_depth, 8);
  // Left: (0 + 1 + 1 + 0) / 4 = 0.5 linear -> 1.055 * 0.5^(1/2.4) - 0.055 = 0.73536 -> 187.5 -> 188.
  for (int c = 0; c < 3; ++c) EXPECT_EQ(t.rgb[c], 188) << "channel " << c;
  // Right: codes 100 (x3) and 200 decode to 0.12744 and 0.57758 (sRGB curve);
  // mean 0.23997 encodes to 0.52709 -> 134.4 -> 134.
  for (int c = 0; c < 3; ++c) EXPECT_EQ(t.rgb[3 + c], 134) << "channel " << c;
  EXPECT_EQ(t.text.at("skyfarm:request"), "{}") << "the source's text chunks are kept";

  // A width at or above the source's: the same pixels at the same size.
  write_png_thumbnail(source, thumb, 10);
  const PngFile same = read_png(thumb);
  EXPECT_EQ(same.width, 4);
  EXPECT_EQ(same.height, 2);
  EXPECT_EQ(same.rgb, std::vector<std::uint16_t>(rgb.begin(), rgb.end()));
  // The height keeps the aspect, at least one row.
  write_png_thumbnail(source, thumb, 1);
  EXPECT_EQ(read_png(thumb).height, 1);
  EXPECT_THROW(write_png_thumbnail(source, thumb, 0), std::invalid_argument);
  EXPECT_THROW(write_png_thumbnail(temp_file("missing"), thumb, 2), std::runtime_error);
  fs::remove(source);
  fs::remove(thumb);
}

}  // namespace
}  // namespace skyfarm
