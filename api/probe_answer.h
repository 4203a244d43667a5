// The answer document of a radiance probe, the same for the CLI
// (`skyfarm-worker probe`) and HTTP (POST /v1/sky/radiance):
//   {"units", "wavelengths_nm", "directions", "radiance": [d][w],
//    "standard_error": [d][w] (null for "lut"), "samples" (null for "lut"),
//    "seed", "method", "approximate", "sun", "nonfinite_paths"}
// The numbers are common/render/probe_answer.h's ProbeAnswer; the request
// gives back what it asked (wavelengths, directions in degrees, samples,
// seed, method).
#pragma once
#include <nlohmann/json.hpp>

#include "api/probe_request.h"
#include "common/render/probe_answer.h"

namespace skyfarm::api {

nlohmann::json probe_answer_json(const ProbeRequest& request, const ProbeAnswer& answer);

}  // namespace skyfarm::api
