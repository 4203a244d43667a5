// The sun disk's pixels, left out of the image-level error estimate.
#include "common/render/sun_pixels.h"

#include <gtest/gtest.h>

#include "tests/support/sun_specs.h"

#include <algorithm>

namespace skyfarm {
namespace {

Sun sun_at(double zenith, double azimuth, double radius = 0.2666) {
  return testing::sun_from_angles(zenith, azimuth, radius);
}

TEST(SunPixels, EquirectCoversTheDiskPixelAndItsNeighbours) {
  CameraSpec cs;
  cs.width = 360;
  cs.height = 180;
  const Camera camera(cs, {0.0, 0.0, 6371000.0});
  const Sun sun = sun_at(30.0, 90.0);  // elevation 60 deg, east: column 3/4 of the width
  const auto pixels = sun_pixels(camera, sun);
  double fx = 0.0, fy = 0.0;
  ASSERT_TRUE(camera.direction_to_film(sun.direction(), &fx, &fy));
  const std::uint32_t centre = static_cast<std::uint32_t>(fy) * 360u + static_cast<std::uint32_t>(fx);
  EXPECT_TRUE(std::binary_search(pixels.begin(), pixels.end(), centre));
  EXPECT_GE(pixels.size(), 1u);
  EXPECT_LE(pixels.size(), 60u) << "a small patch, not the sky";
  EXPECT_TRUE(std::is_sorted(pixels.begin(), pixels.end()));
}

TEST(SunPixels, NoneForAPointSunOrASunOutOfView) {
  CameraSpec cs;
  cs.width = 64;
  cs.height = 32;
  const Camera equirect(cs, {0.0, 0.0, 6371000.0});
  EXPECT_TRUE(sun_pixels(equirect, sun_at(30.0, 90.0, 0.0)).empty());
  cs.projection = Projection::kPerspective;
  cs.yaw_deg = 0.0;  // looking north
  const Camera north(cs, {0.0, 0.0, 6371000.0});
  EXPECT_TRUE(sun_pixels(north, sun_at(60.0, 180.0)).empty());  // sun in the south
}

}  // namespace
}  // namespace skyfarm
