#include "common/render/radiance_probe.h"

#include <cmath>

#include "common/render/parallel.h"

namespace skyfarm {

ProbeResult probe_radiance(const Scene& scene, const std::vector<glm::dvec3>& directions,
                           const std::vector<double>& wavelengths_nm, int samples, std::uint64_t seed,
                           int threads) {
  const VolumePathIntegrator integrator(scene);
  const std::size_t pairs = directions.size() * wavelengths_nm.size();
  const std::size_t blocks = static_cast<std::size_t>((samples + kProbeBlock - 1) / kProbeBlock);
  struct BlockSums {
    double sum = 0.0, sum_sq = 0.0;
    PathCounters counters;
  };
  std::vector<BlockSums> sums(pairs * blocks);
  parallel_for(pairs * blocks, threads, [&](std::size_t task, int) {
    const std::size_t pair = task / blocks, block = task % blocks;
    const glm::dvec3& d = directions[pair / wavelengths_nm.size()];
    const double lambda = wavelengths_nm[pair % wavelengths_nm.size()];
    // Monochromatic: every wavelength slot is the asked wavelength (pdf 1).
    SampledWavelengths wl;
    wl.lambda_nm.fill(lambda);
    wl.pdf.fill(1.0);
    BlockSums& out = sums[task];
    const int s0 = static_cast<int>(block) * kProbeBlock;
    const int s1 = std::min(samples, s0 + kProbeBlock);
    for (int s = s0; s < s1; ++s) {
      Sampler sampler(seed, pair, static_cast<std::uint64_t>(s));
      const double L = integrator.radiance(Ray{scene.observer(), d}, wl, sampler, &out.counters)[0];
      out.sum += L;
      out.sum_sq += L * L;
    }
  });
  ProbeResult r;
  r.radiance.assign(directions.size(), std::vector<double>(wavelengths_nm.size(), 0.0));
  r.standard_error = r.radiance;
  for (std::size_t pair = 0; pair < pairs; ++pair) {
    double sum = 0.0, sum_sq = 0.0;
    for (std::size_t b = 0; b < blocks; ++b) {
      sum += sums[pair * blocks + b].sum;
      sum_sq += sums[pair * blocks + b].sum_sq;
      r.counters.add(sums[pair * blocks + b].counters);
    }
    const double n = samples;
    const double mean = sum / n;
    const double var = n > 1 ? std::max(0.0, (sum_sq - n * mean * mean) / (n - 1.0)) : 0.0;
    r.radiance[pair / wavelengths_nm.size()][pair % wavelengths_nm.size()] = mean;
    r.standard_error[pair / wavelengths_nm.size()][pair % wavelengths_nm.size()] = std::sqrt(var / n);
  }
  return r;
}

}  // namespace skyfarm
