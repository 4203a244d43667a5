// The thin-layer test atmosphere of the single-scattering oracles: a
// homogeneous Henyey-Greenstein scatterer sigma_s (1/m, at 550 nm) from the
// ground to `top` (m), black ground, nothing else.
#pragma once
#include "common/atmosphere/atmosphere_spec.h"

namespace skyfarm::testing {

inline AtmosphereSpec thin_hg_layer(double sigma_s, double top, double g) {
  AtmosphereSpec spec;
  spec.preset = AtmospherePreset::kCustom;
  spec.top_altitude_m = top;
  spec.ground_albedo = 0.0;
  ConstituentSpec layer;
  layer.name = "layer";
  layer.density = LayersDensity{{{0.0, 0.0, 0.0, 0.0, 1.0}}};
  layer.scattering_per_m = {{550.0}, {sigma_s}};
  layer.phase = HenyeyGreensteinPhaseSpec{g};
  spec.constituents = {layer};
  return spec;
}

}  // namespace skyfarm::testing
