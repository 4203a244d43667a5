// The renderer's spec of a probe request (common/render/probe_answer.h): the
// translation from a validated request, field for field; the directions
// become unit vectors in the observer frame and unit_text_bytes the size of
// the request's canonical text, which every farm unit carries.
#pragma once
#include "api/probe_request.h"
#include "common/render/probe_answer.h"

namespace skyfarm::api {

ProbeSpec probe_spec(const ProbeRequest& request);

}  // namespace skyfarm::api
