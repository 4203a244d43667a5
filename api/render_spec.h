// The renderer's spec of a render request (common/render/render_setup.h):
// the translation from a validated request, field for field, and the two
// shorthands the job service uses with a request in hand.  Nothing here
// decides how a render is cut or traced; that is common/render/render_setup.h.
#pragma once
#include "api/render_request.h"
#include "common/film/error_estimate.h"
#include "common/film/image.h"
#include "common/render/render_plan.h"
#include "common/render/render_setup.h"
#include "common/sun/sun.h"

namespace skyfarm::api {

RenderSpec render_spec(const RenderRequest& request);

// render_plan_for(render_spec(request), sun).
RenderPlan render_plan_for(const RenderRequest& request, const Sun& sun);

// set_render_metadata with the request's canonical text.
void set_render_metadata(Image* image, const RenderRequest& request, const RenderPlan& plan, const Sun& sun,
                         double samples_per_pixel, const ErrorSums& error);

}  // namespace skyfarm::api
