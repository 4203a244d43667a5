// A physical report of a request's sky without rendering it: the sun's
// position and distance, where it appears once refracted (apparent_sun:
// ray-traced US76 at 550 nm for the observer's altitude, beside the SPA's
// Bennett correction; the request's or the SPA's angles are taken as
// geometric), the atmosphere's constituents and their optical depths, and the
// direct sun's transmittance.  `skyfarm-worker info`.
#pragma once
#include <nlohmann/json.hpp>

#include "api/render_request.h"

namespace skyfarm {

// The report as JSON (stable field names; see `skyfarm-worker info --json`).
nlohmann::json sky_report(const api::RenderRequest& request);

// The same, laid out for a terminal.
std::string format_sky_report(const nlohmann::json& report);

}  // namespace skyfarm
