// A coarse LUT resolution for tests: tables in ~5-50 ms instead of ~0.2 s,
// good enough for colours, layouts and caching (not for accuracy tests).
#pragma once
#include "common/lut/lut_sky.h"

namespace skyfarm {

inline LutResolution coarse_lut_resolution(int spectral_bins) {
  LutResolution r;
  r.spectral_bins = spectral_bins;
  r.medium_altitude_samples = 256;
  r.phase_samples = 128;
  r.transmittance_mu = 64, r.transmittance_r = 32, r.transmittance_steps = 24;
  r.multiple_scattering_mu_s = 8, r.multiple_scattering_altitude = 8;
  r.multiple_scattering_directions = 16, r.multiple_scattering_steps = 8;
  r.ground_irradiance_mu_s = 8, r.ground_irradiance_directions = 16, r.ground_irradiance_steps = 8;
  r.sky_view_azimuth = 48, r.sky_view_zenith = 36, r.sky_view_steps = 12;
  r.aerial_azimuth = 4, r.aerial_zenith = 4, r.aerial_slices = 4;
  r.space_view_steps = 16;
  return r;
}

}  // namespace skyfarm
