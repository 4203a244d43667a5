#include "api/render_setup.h"

namespace skyfarm::api {

RenderSetup make_render_setup(const RenderRequest& request) {
  RenderSetup s;
  s.scene = std::make_unique<Scene>(Scene::from_specs(request.atmosphere, request.sun, request.location, request.time,
                                                      request.spectral.min_nm, request.spectral.max_nm));
  s.camera = std::make_unique<Camera>(request.camera, s.scene->observer());
  s.plan = make_render_plan(request.camera.width, request.camera.height, request.spectral.min_nm,
                            request.spectral.max_nm, request.spectral.batches, request.quality.samples_per_pixel,
                            request.seed);
  return s;
}

}  // namespace skyfarm::api
