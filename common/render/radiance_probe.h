// Monochromatic radiance in given directions from the observer
// (`skyfarm-worker probe`, DESIGN §5.2): for each direction and each
// wavelength, the mean of `samples` path-traced estimates at exactly that
// wavelength and its standard error (sample standard deviation / sqrt(n)).
// Work is cut into blocks of kProbeBlock samples summed in a fixed order,
// so the answer does not depend on the number of threads.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "common/render/scene.h"
#include "common/render/volume_path_integrator.h"

namespace skyfarm {

inline constexpr int kProbeBlock = 256;

struct ProbeResult {
  std::vector<std::vector<double>> radiance;        // [direction][wavelength], W m^-2 sr^-1 nm^-1
  std::vector<std::vector<double>> standard_error;  // same layout
  PathCounters counters;
};

// directions: unit vectors in the observer frame (z up, y north, x east).
ProbeResult probe_radiance(const Scene& scene, const std::vector<glm::dvec3>& directions,
                           const std::vector<double>& wavelengths_nm, int samples, std::uint64_t seed,
                           int threads = 0);

}  // namespace skyfarm
