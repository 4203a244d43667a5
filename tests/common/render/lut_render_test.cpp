// method "lut" through the tile renderer: the image of the LUT renderer
// against the path tracer's on the same request (the LUT is approximate:
// Hillaire's isotropic multiple scattering and per-bin spectra; the bounds
// below are the measured agreement with margin, README "LUT accuracy"), the
// sun disk's energy (8 x 8 supersampled pixels), and finite, >= 0 pixels.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "api/render_request.h"
#include "api/render_spec.h"
#include "common/render/local_render.h"

namespace skyfarm {
namespace {

struct Rendered {
  RenderSetup setup;
  Image image{1, 1};
};

Rendered render(const std::string& json) {
  Rendered r;
  r.setup = make_render_setup(api::render_spec(api::parse_render_request(json)));
  const TileRenderer renderer(*r.setup.scene, *r.setup.camera, r.setup.plan);
  r.image = Image(r.setup.plan.width, r.setup.plan.height);
  const LocalRenderResult result = render_image(renderer, &r.image, 2);
  EXPECT_EQ(result.counters.nonfinite, 0u);
  return r;
}

std::string request(const char* method, const char* camera, int spp) {
  return std::string(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 180}, "camera": )") + camera +
         R"(, "spectral": {"batches": 2}, "quality": {"samples_per_pixel": )" + std::to_string(spp) +
         R"(}, "method": ")" + method + R"(", "output": {"half": false}, "seed": 11})";
}

TEST(LutRender, SkyAgreesWithThePathTracer) {
  const char* camera = R"({"projection": "equirectangular", "width": 64, "height": 32})";
  const Rendered lut = render(request("lut", camera, 1));
  const Rendered path = render(request("path", camera, 256));
  EXPECT_TRUE(lut.setup.plan.lut);
  EXPECT_EQ(lut.setup.plan.passes, 1);
  const auto sun = lut.setup.scene->sun().direction();
  double num = 0.0, den = 0.0, sum_lut = 0.0, sum_path = 0.0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      const double a = lut.image.luminance(x, y), b = path.image.luminance(x, y);
      ASSERT_TRUE(std::isfinite(a) && a >= 0.0) << x << ", " << y;
      Ray ray;
      ASSERT_TRUE(lut.setup.camera->generate_ray(x, y, 0.5, 0.5, &ray));
      if (glm::dot(ray.d, sun) > std::cos(0.1)) continue;  // the sun's pixels: below
      const double w = lut.setup.camera->pixel_solid_angle(x, y);
      num += w * (a - b) * (a - b);
      den += w * b * b;
      sum_lut += w * a;
      sum_path += w * b;
    }
  // Measured: relative RMS difference 0.05, mean luminance within 1 % (the
  // path tracer's own noise at 256 spp is ~0.03 RMS).
  EXPECT_LT(std::sqrt(num / den), 0.12);
  EXPECT_NEAR(sum_lut / sum_path, 1.0, 0.04);
}

TEST(LutRender, SunDiskEnergyMatchesThePathTracer) {
  // A narrow view centred on the sun: the disk covers a few pixels.
  const char* camera =
      R"({"projection": "perspective", "width": 24, "height": 24, "yaw_deg": 180, "pitch_deg": 50, "fov_deg": 2})";
  const Rendered lut = render(request("lut", camera, 1));
  const Rendered path = render(request("path", camera, 64));
  double e_lut = 0.0, e_path = 0.0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) {
      const double w = lut.setup.camera->pixel_solid_angle(x, y);
      e_lut += w * lut.image.luminance(x, y);
      e_path += w * path.image.luminance(x, y);
    }
  // The disk dominates (~1e9 cd/m2 over 7e-5 sr); both integrate it over
  // the pixels, the path tracer by jittered samples (64 per pixel).
  EXPECT_NEAR(e_lut / e_path, 1.0, 0.03);
}

}  // namespace
}  // namespace skyfarm
