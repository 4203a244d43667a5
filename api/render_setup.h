// From a validated render request to what renders it: the scene (atmosphere,
// sun, observer, majorants), the camera and the render plan.  Shared by the
// local renderer, the benchmarks and the farm, so all of them cut a request
// into the same units of work.
#pragma once
#include <memory>

#include "api/render_request.h"
#include "common/camera/camera.h"
#include "common/render/render_plan.h"
#include "common/render/scene.h"

namespace skyfarm::api {

struct RenderSetup {
  std::unique_ptr<Scene> scene;
  std::unique_ptr<Camera> camera;
  RenderPlan plan;
};

RenderSetup make_render_setup(const RenderRequest& request);

}  // namespace skyfarm::api
