// The answer to a radiance probe, the same for the CLI
// (`skyfarm-worker probe`) and HTTP (POST /v1/sky/radiance):
//   {"units", "wavelengths_nm", "directions", "radiance": [d][w],
//    "standard_error": [d][w] (null for "lut"), "samples" (null for "lut"),
//    "seed", "method", "approximate", "sun", "nonfinite_paths"}
// Nothing in it depends on how or where the probe ran (no timings), so the
// farm's answer and the CLI's are the same document, number for number.
// "path" traces the probe's units (common/render/probe_units.h) on `threads`
// threads (0: all cores), with the roulette's control variate when the sun
// is up to 85 deg from the zenith (probe_roulette_control, as for renders);
// "lut" answers from one-bin tables per wavelength (common/lut/lut_probe.h).
//
// The probe's cut into units is probe_plan(): ProbePlan::make(directions x
// wavelengths, samples, max_units) with max_units = 4096, fewer for a long
// request (every unit carries the request's text: max_units x text stays
// under 256 MiB, and never below 64 units).  The farm (server/probes/probe_service.h,
// the worker) and the CLI all use it, which is what makes their answers equal.
#pragma once
#include <memory>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "api/probe_request.h"
#include "common/render/probe_units.h"
#include "common/render/scene.h"

namespace skyfarm::api {

// The scene a probe is traced in: majorants over the asked wavelengths +-0.5 nm.
Scene probe_scene(const ProbeRequest& request);
// The directions as unit vectors in the observer frame (x east, y north, z up).
std::vector<glm::dvec3> probe_directions(const ProbeRequest& request);
ProbePlan probe_plan(const ProbeRequest& request);
// The roulette's control variate for a "path" probe whose sun is up to
// RenderPlan::kRouletteControlMaxSunZenith_deg from the zenith (as for
// renders), built from its scene; null otherwise.  The CLI and the farm's
// workers both trace with it, so their answers stay equal.
std::shared_ptr<const RadianceControl> probe_roulette_control(const ProbeRequest& request, const Scene& scene);

// The "path" answer from the reduced result.
nlohmann::json path_probe_answer(const ProbeRequest& request, const ProbeResult& result);
// The whole answer, traced (or looked up) on this machine.
nlohmann::json answer_probe(const ProbeRequest& request, int threads);

}  // namespace skyfarm::api
