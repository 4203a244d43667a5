#include "api/render_setup.h"

namespace skyfarm::api {

RenderSetup make_render_setup(const RenderRequest& request) {
  RenderSetup s;
  s.scene = std::make_unique<Scene>(Scene::from_specs(request.atmosphere, request.sun, request.location, request.time,
                                                      request.spectral.min_nm, request.spectral.max_nm));
  s.camera = std::make_unique<Camera>(request.camera, s.scene->observer());
  s.plan = render_plan_for(request, s.scene->sun());
  return s;
}

RenderPlan render_plan_for(const RenderRequest& request, const Sun& sun) {
  constexpr int kTileSize = 32, kSamplesPerPass = 16;
  const bool lut = request.method == Method::kLut;
  // The LUT renderer is deterministic: one sample per pixel and batch, one pass.
  RenderPlan plan = make_render_plan(request.camera.width, request.camera.height, request.spectral.min_nm,
                                     request.spectral.max_nm, request.spectral.batches,
                                     lut ? 1 : request.quality.samples_per_pixel, request.seed, kTileSize,
                                     lut ? 1 : kSamplesPerPass,
                                     mirror_symmetric(request.camera, sun.azimuth_deg(), kTileSize));
  plan.lut = lut;
  plan.roulette_control = !lut && roulette_control_pays(sun.zenith_deg());
  plan.shadow_guide = !lut && shadow_guide_pays(sun.zenith_deg());
  plan.adaptive = !lut && request.quality.adaptive && plan.passes >= 2;
  // An observer on the ground sees one ground point in every downward
  // direction (common/film/ground_pool.h).
  if (!lut && request.location.altitude_m == 0.0) plan.pooled_ground_row = first_ground_row(request.camera);
  return plan;
}

}  // namespace skyfarm::api

namespace skyfarm::api {

void set_render_metadata(Image* image, const RenderRequest& request, const RenderPlan& plan, const Sun& sun,
                         double samples_per_pixel, const ErrorSums& error) {
  namespace key = metadata_key;
  image->set_metadata(key::kRequest, canonical_text(request));
  image->set_metadata(key::kSunZenithDeg, sun.zenith_deg());
  image->set_metadata(key::kSunAzimuthDeg, sun.azimuth_deg());
  image->set_metadata(key::kSamplesPerPixel, static_cast<double>(samples_per_pixel));
  image->set_metadata(key::kWavelengthMinNm, plan.lambda_min_nm);
  image->set_metadata(key::kWavelengthMaxNm, plan.lambda_max_nm);
  image->set_metadata(key::kSoftwareVersion, std::string("skyfarm ") + SKYFARM_VERSION);
  if (const auto e = error.relative_rms()) image->set_metadata(key::kEstimatedRelativeRms, *e);
  if (const auto e = error.relative_rms_rgb()) {
    image->set_metadata(key::kEstimatedRelativeRmsR, e->r);
    image->set_metadata(key::kEstimatedRelativeRmsG, e->g);
    image->set_metadata(key::kEstimatedRelativeRmsB, e->b);
  }
  image->set_metadata("method", std::string(plan.lut ? "lut" : "path"));
  if (plan.lut)
    image->set_metadata("approximate", std::string("table-based sky (Hillaire 2020); error against the path tracer: README"));
  image->set_metadata("earth_sun_distance_au", sun.distance_au());
}

}  // namespace skyfarm::api
