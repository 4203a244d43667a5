#include "api/render_spec.h"

namespace skyfarm::api {

RenderSpec render_spec(const RenderRequest& request) {
  RenderSpec spec;
  spec.location = request.location;
  spec.time = request.time;
  spec.sun = request.sun;
  spec.atmosphere = request.atmosphere;
  spec.objects = request.objects;
  spec.clouds = request.clouds;
  spec.camera = request.camera;
  spec.lambda_min_nm = request.spectral.min_nm;
  spec.lambda_max_nm = request.spectral.max_nm;
  spec.batches = request.spectral.batches;
  spec.samples_per_pixel = request.quality.samples_per_pixel;
  spec.adaptive = request.quality.adaptive;
  spec.lut = request.method == Method::kLut;
  spec.seed = request.seed;
  return spec;
}

RenderPlan render_plan_for(const RenderRequest& request, const Sun& sun) {
  return skyfarm::render_plan_for(render_spec(request), sun);
}

void set_render_metadata(Image* image, const RenderRequest& request, const RenderPlan& plan, const Sun& sun,
                         double samples_per_pixel, const ErrorSums& error) {
  skyfarm::set_render_metadata(image, canonical_text(request), plan, sun, samples_per_pixel, error);
}

}  // namespace skyfarm::api
