// What a request says about a surface: which material, how rough, which
// microfacet model, and whether light may bounce more than once on it.
//
// Parameters (the request's "material" object; api/ validates and fills it)
//   name             a named material (material_library.h: gold, water,
//                    snow, ...) or, with tables, the label of a custom one
//   kind             custom only: conductor, dielectric or diffuse
//   wavelengths_nm   custom only: the tables' wavelengths, increasing
//   n, k             custom conductor or dielectric: the complex index
//                    (k may be empty for a dielectric: k = 0)
//   albedo           custom diffuse: the albedo at each wavelength
//   roughness_x/y    the microfacet alpha along east (x) and north (y),
//                    0 (smooth: a mirror for a conductor or dielectric, a
//                    Lambertian surface for a diffuse one) or in
//                    [kMinRoughness, kMaxRoughness]; equal for an isotropic
//                    surface
//   distribution     GGX (Trowbridge-Reitz, default) or Beckmann
//   multiple_bounce  true (default): the position-free multiple-bounce BSDF,
//                    energy conserving; false: the single-bounce BSDF
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "common/material/material_library.h"
#include "common/material/microfacet_distribution.h"

namespace skyfarm::material {

inline constexpr double kMinRoughness = 1e-3;
inline constexpr double kMaxRoughness = 2.0;

struct SurfaceSpec {
  std::string name;
  bool custom = false;
  MaterialKind kind = MaterialKind::kDiffuse;  // custom only; named: the material's
  std::vector<double> wavelengths_nm, n, k, albedo;
  double roughness_x = 0.0, roughness_y = 0.0;
  MicrofacetModel distribution = MicrofacetModel::ggx;
  bool multiple_bounce = true;

  bool smooth() const { return roughness_x == 0.0 && roughness_y == 0.0; }
  bool isotropic() const { return roughness_x == roughness_y; }
};

}  // namespace skyfarm::material
