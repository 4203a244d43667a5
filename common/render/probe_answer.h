// A radiance probe answered on this machine, the same for the CLI
// (`skyfarm-worker probe`) and HTTP (POST /v1/sky/radiance): the radiance in
// each direction at each wavelength, its standard error ("path" only), the
// sun's position and the count of non-finite paths.  Nothing in it depends on
// how or where the probe ran (no timings), so the farm's answer and the CLI's
// are the same, number for number.
//
// "path" traces the probe's units (probe_units.h) on `threads` threads (0:
// all cores), with the roulette's control variate when the sun is up to
// RenderPlan::kRouletteControlMaxSunZenith_deg from the zenith (as for
// renders); "lut" answers from one-bin tables per wavelength
// (common/lut/lut_probe.h).
//
// The probe's cut into units is probe_plan(): ProbePlan::make(directions x
// wavelengths, samples, max_units) with max_units = kProbeDefaultMaxUnits
// (4096), fewer for a long request (every farm unit carries the request's
// text, unit_text_bytes: max_units x text stays under 256 MiB, and never
// below 64 units).  The farm (its probe service and workers) and the CLI all
// use it, which is what makes their answers equal.
//
// The spec holds no request: the API translates a validated probe request
// into one (api/probe_spec.h) and writes the answer's JSON document
// (api/probe_answer.h).
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "common/atmosphere/atmosphere_spec.h"
#include "common/render/probe_units.h"
#include "common/render/radiance_control.h"
#include "common/render/radiance_probe.h"
#include "common/render/scene.h"
#include "common/sun/sun_spec.h"
#include "common/sun/utc_time.h"

namespace skyfarm {

struct ProbeSpec {
  // The scene (Scene::from_specs).
  Location location;
  std::optional<UtcInstant> time;
  SunSpec sun;
  AtmosphereSpec atmosphere;
  // Unit vectors in the observer frame (x east, y north, z up).
  std::vector<glm::dvec3> directions;
  std::vector<double> wavelengths_nm;
  int samples = 4096;  // per direction and wavelength ("path")
  std::uint64_t seed = 1;
  bool lut = false;  // one-bin tables instead of the path tracer
  // The bytes each farm unit carries besides its numbers (the request's
  // canonical text); a longer text makes fewer units.
  std::size_t unit_text_bytes = 1;
};

struct ProbeAnswer {
  std::vector<std::vector<double>> radiance;  // [direction][wavelength], W m^-2 sr^-1 nm^-1
  std::optional<std::vector<std::vector<double>>> standard_error;  // same layout; "path" only
  std::uint64_t nonfinite_paths = 0;
  double sun_zenith_deg = 0.0, sun_azimuth_deg = 0.0;
};

// The scene a probe is traced in: majorants over the asked wavelengths +-0.5 nm.
Scene probe_scene(const ProbeSpec& spec);
ProbePlan probe_plan(const ProbeSpec& spec);
// The roulette's control variate for a "path" probe whose sun is up to
// RenderPlan::kRouletteControlMaxSunZenith_deg from the zenith (as for
// renders), built from its scene; null otherwise.  The CLI and the farm's
// workers both trace with it, so their answers stay equal.
std::shared_ptr<const RadianceControl> probe_roulette_control(const ProbeSpec& spec, const Scene& scene);

// The "path" answer from the reduced result.
ProbeAnswer path_probe_answer(const ProbeSpec& spec, const ProbeResult& result);
// The whole answer, traced (or looked up) on this machine.
ProbeAnswer answer_probe(const ProbeSpec& spec, int threads);

}  // namespace skyfarm
