// The atmosphere as a request describes it (field names in the comments).
// Plain data: parsed and validated by api/, turned into a physical
// model by build_atmosphere() (common/atmosphere/atmosphere_builder.h).
#pragma once
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/core/spectral_table.h"
#include "common/material/surface_spec.h"

namespace skyfarm {

// --- Density profiles of a constituent (dimensionless multiplier of its
// per-metre coefficients).

// {"type": "exponential", "scale_height_m": H}: rho(h) = exp(-h / H).
struct ExponentialDensity {
  double scale_height_m = 8000.0;
};
// {"type": "table", "altitude_m": [...], "values": [...]}: piecewise linear,
// zero below the first and above the last altitude.
struct TableDensity {
  std::vector<double> altitude_m;
  std::vector<double> values;
};
// One layer of Bruneton's (2017) DensityProfileLayer:
// rho(h) = exp_term * exp(exp_scale_per_m * h) + linear_term_per_m * h + constant_term,
// clamped to [0, 1]; layers stack upwards, the last one extends to the top.
struct DensityLayer {
  double width_m = 0.0;
  double exp_term = 0.0;
  double exp_scale_per_m = 0.0;
  double linear_term_per_m = 0.0;
  double constant_term = 0.0;
};
struct LayersDensity {
  std::vector<DensityLayer> layers;
};
using DensitySpec = std::variant<ExponentialDensity, TableDensity, LayersDensity>;

// --- Phase functions.
// {"type": "rayleigh", "depolarization": rho_n}
struct RayleighPhaseSpec {
  double depolarization = 0.0;
};
// {"type": "henyey_greenstein", "g": g}
struct HenyeyGreensteinPhaseSpec {
  double g = 0.0;
};
// {"type": "cornette_shanks", "g": g}
struct CornetteShanksPhaseSpec {
  double g = 0.0;
};
// {"type": "table", "angles_deg": [...], "values": [...]}: any positive scale;
// normalised to integrate to 1 over the sphere when built.
struct TablePhaseSpec {
  std::vector<double> angles_deg;
  std::vector<double> values;
};
using PhaseSpec =
    std::variant<RayleighPhaseSpec, HenyeyGreensteinPhaseSpec, CornetteShanksPhaseSpec, TablePhaseSpec>;

// One entry of "atmosphere.constituents".
struct ConstituentSpec {
  std::string name;
  DensitySpec density;
  SpectralTable scattering_per_m;  // at density 1; empty table = 0
  SpectralTable absorption_per_m;  // at density 1; empty table = 0
  PhaseSpec phase = HenyeyGreensteinPhaseSpec{0.0};
};

enum class AerosolPhase { kHenyeyGreenstein, kCornetteShanks };

// "atmosphere.aerosol"
struct AerosolSpec {
  double optical_depth_550 = 0.1;
  double angstrom_exponent = 1.3;
  double asymmetry = 0.7;
  double single_scattering_albedo = 0.9;
  AerosolPhase phase = AerosolPhase::kHenyeyGreenstein;
};

enum class AtmospherePreset { kEarth, kEarthClear, kCustom };

// "atmosphere.ground_albedo": a number or a spectral table.
using AlbedoSpec = std::variant<double, SpectralTable>;

// "atmosphere"
struct AtmosphereSpec {
  AtmospherePreset preset = AtmospherePreset::kEarth;
  double ozone_du = 300.0;               // earth presets only
  std::optional<AerosolSpec> aerosol = AerosolSpec{};  // nullopt: no aerosols
  AlbedoSpec ground_albedo = 0.3;
  // "atmosphere.ground.material": when set, the ground is this surface and
  // ground_albedo is not used (the Lambertian ground of the tables is the
  // surface's white-sky albedo, material/surface.h).
  std::optional<material::SurfaceSpec> ground_material;
  double planet_radius_m = 6371000.0;
  double top_altitude_m = 100000.0;
  std::vector<ConstituentSpec> constituents;  // custom preset only
  // "atmosphere.refraction": rays bend in the air (Ciddor's index of US76,
  // docs/physics.md, "Refraction"); off, the renderers trace straight rays.
  bool refraction = false;
};

}  // namespace skyfarm
