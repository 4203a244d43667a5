// From a validated render request to what renders it: the scene (atmosphere,
// sun, observer, majorants), the camera and the render plan.  Shared by the
// local renderer, the benchmarks and the farm, so all of them cut a request
// into the same units of work.
#pragma once
#include <memory>

#include "api/render_request.h"
#include "common/camera/camera.h"
#include "common/film/error_estimate.h"
#include "common/film/image.h"
#include "common/render/render_plan.h"
#include "common/render/scene.h"

namespace skyfarm::api {

struct RenderSetup {
  std::unique_ptr<Scene> scene;
  std::unique_ptr<Camera> camera;
  RenderPlan plan;
};

RenderSetup make_render_setup(const RenderRequest& request);

// The plan of a request (tiles, batches, passes, mirror symmetry), given its sun.
RenderPlan render_plan_for(const RenderRequest& request, const Sun& sun);

// The metadata every rendered image carries (EXR attributes, PNG text), the
// same for `skyfarm-worker render` and the farm so their files are identical:
// canonical request, sun position, samples, wavelength range, version,
// method and the estimated error.
void set_render_metadata(Image* image, const RenderRequest& request, const RenderPlan& plan, const Sun& sun,
                         double samples_per_pixel, const ErrorSums& error);

}  // namespace skyfarm::api
