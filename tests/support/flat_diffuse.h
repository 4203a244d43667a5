// A custom diffuse surface of the same albedo at every wavelength (a
// Lambertian reflector once smooth): the grey and white test objects.
#pragma once

#include "common/material/surface_spec.h"

namespace skyfarm::testing {

inline material::SurfaceSpec flat_diffuse(double albedo) {
  material::SurfaceSpec s;
  s.name = "flat diffuse";
  s.custom = true;
  s.kind = material::MaterialKind::kDiffuse;
  s.wavelengths_nm = {300.0, 900.0};
  s.albedo = {albedo, albedo};
  return s;
}

}  // namespace skyfarm::testing
