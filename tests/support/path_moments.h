// The mean and variance of one camera path's radiance at 550 nm (all four
// wavelength slots at 550 nm) along a view, with a chosen surface sun
// sampling and MIS heuristic: what the MIS tests compare between strategies.
// Counts non-finite paths into *nonfinite (if given).
#pragma once

#include <algorithm>
#include <cstdint>

#include "common/render/volume_path_integrator.h"

namespace skyfarm::testing {

struct PathMoments {
  double mean = 0.0, variance = 0.0;
};

inline PathMoments path_moments(const Scene& scene, const glm::dvec3& view, SurfaceSunSampling strategy,
                                SurfaceMisHeuristic heuristic, int n, std::uint64_t seed,
                                std::uint64_t* nonfinite = nullptr) {
  IntegratorOptions options;
  options.surface_sun_sampling = strategy;
  options.surface_mis_heuristic = heuristic;
  const VolumePathIntegrator integrator(scene, options);
  SampledWavelengths wl;
  wl.lambda_nm.fill(550.0);
  wl.pdf.fill(1.0);
  PathCounters counters;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    Sampler sampler(seed, 0, static_cast<std::uint64_t>(i));
    const double L = integrator.radiance(Ray{scene.observer(), view}, wl, sampler, &counters)[0];
    sum += L;
    sum2 += L * L;
  }
  if (nonfinite) *nonfinite += counters.nonfinite;
  const double mean = sum / n;
  return {mean, std::max(0.0, sum2 / n - mean * mean)};
}

}  // namespace skyfarm::testing
