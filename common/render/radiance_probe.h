// Monochromatic radiance in given directions from the observer
// (`skyfarm-worker probe`): for each direction and each
// wavelength, the mean of `samples` path-traced estimates at exactly that
// wavelength and its standard error (sample standard deviation / sqrt(n)).
// The work is the probe's units (probe_units.h) traced on local threads and
// reduced in canonical order, so the answer does not depend on the number
// of threads and equals the farm's for the same plan.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "common/render/scene.h"
#include "common/render/volume_path_integrator.h"

namespace skyfarm {

struct ProbeResult {
  std::vector<std::vector<double>> radiance;        // [direction][wavelength], W m^-2 sr^-1 nm^-1
  std::vector<std::vector<double>> standard_error;  // same layout
  PathCounters counters;
};

struct ProbePlan;

// directions: unit vectors in the observer frame (z up, y north, x east).
// Cut by ProbePlan::make(directions x wavelengths, samples) (default max_units).
ProbeResult probe_radiance(const Scene& scene, const std::vector<glm::dvec3>& directions,
                           const std::vector<double>& wavelengths_nm, int samples, std::uint64_t seed,
                           int threads = 0);
// The same cut by `plan` (plan.pairs must be directions x wavelengths),
// with the roulette's control variate if one is given.
ProbeResult probe_radiance(const Scene& scene, const std::vector<glm::dvec3>& directions,
                           const std::vector<double>& wavelengths_nm, const ProbePlan& plan, std::uint64_t seed,
                           int threads = 0, std::shared_ptr<const RadianceControl> control = nullptr);

}  // namespace skyfarm
