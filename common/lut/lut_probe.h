// Monochromatic radiance in given directions from the LUT renderer (the
// `"method": "lut"` of `skyfarm-worker probe` and POST /v1/sky/radiance):
// for each asked wavelength, tables with ONE spectral bin of
// width 1 nm centred on it (so the value is the radiance at that wavelength
// of the sun's spectrum averaged over 1 nm, like the path tracer's), then a
// look-up per direction, sun disk included.  Deterministic: no standard
// error (the LUT's error is its bias against the path tracer, README).
#pragma once
#include <glm/vec3.hpp>
#include <vector>

#include "common/atmosphere/atmosphere.h"
#include "common/sun/sun.h"

namespace skyfarm {

// radiance[d][w], W m^-2 sr^-1 nm^-1; directions are unit vectors in the
// observer frame (z up, y north, x east).  refraction: the sky seen
// through it (LutSky::refracted).
std::vector<std::vector<double>> probe_radiance_lut(const Atmosphere& atmosphere, const Sun& sun,
                                                    double observer_altitude_m,
                                                    const std::vector<glm::dvec3>& directions,
                                                    const std::vector<double>& wavelengths_nm,
                                                    bool refraction = false);

}  // namespace skyfarm
