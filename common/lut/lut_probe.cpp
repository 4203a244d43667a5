#include "common/lut/lut_probe.h"

#include <array>

#include "common/lut/lut_sky.h"

namespace skyfarm {

std::vector<std::vector<double>> probe_radiance_lut(const Atmosphere& atmosphere, const Sun& sun,
                                                    double observer_altitude_m,
                                                    const std::vector<glm::dvec3>& directions,
                                                    const std::vector<double>& wavelengths_nm, bool refraction) {
  std::vector<std::vector<double>> radiance(directions.size(), std::vector<double>(wavelengths_nm.size(), 0.0));
  LutResolution one_bin;
  one_bin.spectral_bins = 1;
  for (std::size_t w = 0; w < wavelengths_nm.size(); ++w) {
    const double lambda = wavelengths_nm[w];
    LutSky sky = LutSky::build(atmosphere, sun, observer_altitude_m, lambda - 0.5, lambda + 0.5, one_bin);
    if (refraction) sky = sky.refracted();
    std::array<double, 1> L{};
    for (std::size_t d = 0; d < directions.size(); ++d) {
      sky.radiance(directions[d], L, true);
      radiance[d][w] = L[0];
    }
  }
  return radiance;
}

}  // namespace skyfarm
