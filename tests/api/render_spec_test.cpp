// The translation of a render request into the renderer's spec
// (api/render_spec.h): every field the renderer reads comes from the
// request, and the image metadata carry the request's canonical text.
#include "api/render_spec.h"

#include <gtest/gtest.h>

#include <string>
#include <variant>

namespace skyfarm::api {
namespace {

TEST(RenderSpec, CarriesTheRequestsChoices) {
  const RenderRequest request = parse_render_request(R"({
      "location": {"latitude_deg": 48.1, "longitude_deg": 11.6, "altitude_m": 520},
      "time": "2026-06-21T18:30:00Z",
      "camera": {"projection": "fisheye", "width": 96, "height": 96, "fov_deg": 180},
      "spectral": {"min_nm": 380, "max_nm": 780, "batches": 2},
      "quality": {"samples_per_pixel": 48, "adaptive": true},
      "method": "lut", "seed": 9})");
  const RenderSpec spec = render_spec(request);
  EXPECT_EQ(spec.location.latitude_deg, 48.1);
  EXPECT_EQ(spec.location.altitude_m, 520.0);
  ASSERT_TRUE(spec.time.has_value());
  EXPECT_EQ(spec.time->unix_seconds, request.time->unix_seconds);
  EXPECT_EQ(spec.camera.projection, Projection::kFisheye);
  EXPECT_EQ(spec.camera.width, 96);
  EXPECT_EQ(spec.camera.fov_deg, 180.0);
  EXPECT_EQ(spec.lambda_min_nm, 380.0);
  EXPECT_EQ(spec.lambda_max_nm, 780.0);
  EXPECT_EQ(spec.batches, 2);
  EXPECT_EQ(spec.samples_per_pixel, 48);
  EXPECT_TRUE(spec.adaptive);
  EXPECT_TRUE(spec.lut);
  EXPECT_EQ(spec.seed, 9u);
  EXPECT_FALSE(render_spec(parse_render_request(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 0},
      "camera": {"projection": "fisheye"}, "method": "path"})")).lut);
}

TEST(RenderSpec, PlanAndMetadataOfARequestAreThoseOfItsSpec) {
  const RenderRequest request = parse_render_request(R"({"sun": {"zenith_deg": 60, "azimuth_deg": 100},
      "camera": {"projection": "equirectangular", "width": 64, "height": 32}})");
  const Sun sun = Sun::from_spec(request.sun, request.location, request.time);
  const RenderPlan plan = render_plan_for(request, sun);
  const RenderPlan direct = skyfarm::render_plan_for(render_spec(request), sun);
  EXPECT_EQ(plan.unit_count(), direct.unit_count());
  EXPECT_EQ(plan.samples_per_pass, direct.samples_per_pass);
  EXPECT_EQ(plan.mirrored, direct.mirrored);
  EXPECT_EQ(plan.roulette_control, direct.roulette_control);
  EXPECT_EQ(plan.pooled_ground_row, direct.pooled_ground_row);
  EXPECT_TRUE(plan.roulette_control) << "sun 60 deg from the zenith";
  Image image(plan.width, plan.height);
  set_render_metadata(&image, request, plan, sun, 64.0, ErrorSums{});
  EXPECT_EQ(std::get<std::string>(image.metadata().at(metadata_key::kRequest)), canonical_text(request));
}

}  // namespace
}  // namespace skyfarm::api
