// The farm worker's probe units (api/wire.h, UNIT kind "probe"): the
// request is a ProbeRequest's canonical text, tile is the unit's index in its
// probe_plan (common/render/probe_answer.h); the answer is a RESULT carrying
// the unit's ProbeUnitSums (common/render/probe_units.h), traced on the
// calling thread exactly as `skyfarm-worker probe` traces that unit, or
// FAILED with the reason (a request that does not parse or is not a "path" probe, a unit
// outside the plan, anything the tracer throws).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "api/probe_request.h"
#include "api/wire.h"
#include "common/render/probe_units.h"
#include "common/render/scene.h"

namespace skyfarm {

// What traces every unit of one probe (cached per job by the worker).
struct ProbeSetup {
  api::ProbeRequest request;
  Scene scene;
  std::vector<glm::dvec3> directions;
  ProbePlan plan;
  std::shared_ptr<const RadianceControl> control;  // probe_roulette_control
};

// Throws std::runtime_error naming what is wrong with the request.
ProbeSetup make_probe_setup(const std::string& request_text);

// RESULT or FAILED for `unit` (its request already set up in `setup`).
api::Message run_probe_unit(const ProbeSetup& setup, const api::UnitMsg& unit);

}  // namespace skyfarm
