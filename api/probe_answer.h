// The answer to a radiance probe (DESIGN §5.2), the same for the CLI
// (`skyfarm-worker probe`) and HTTP (POST /v1/sky/radiance):
//   {"units", "wavelengths_nm", "directions", "radiance": [d][w],
//    "standard_error": [d][w] (null for "lut"), "method", "approximate",
//    "samples", "seed", "sun", "elapsed_s", "nonfinite_paths"}
// "path" traces `samples` paths per direction and wavelength on `threads`
// threads (0: all cores); "lut" answers from one-bin tables per wavelength
// (common/lut/lut_probe.h).
#pragma once
#include <nlohmann/json.hpp>

#include "api/probe_request.h"

namespace skyfarm::api {

nlohmann::json answer_probe(const ProbeRequest& request, int threads);

}  // namespace skyfarm::api
