// "atmosphere.ground": the ground as a material, read and written.
//
//   "ground": {"material": {
//     "name": "water",              a named material (material_library.h), or
//                                   with tables the label of a custom one
//     "kind": "dielectric",         custom only: conductor | dielectric | diffuse
//     "wavelengths_nm": [...],      custom only, increasing, in [230, 2500]
//     "n": [...], "k": [...],       custom conductor (both) / dielectric (k optional)
//     "albedo": [...],              custom diffuse, each in [0, 1]
//     "roughness": 0.1,             microfacet alpha, or [alpha_east, alpha_north];
//                                   0 = smooth; else in [0.001, 2]; default 0
//     "distribution": "ggx",        ggx | beckmann
//     "multiple_bounce": true}}     the position-free multiple-bounce BSDF
//
// Every error names its field; the request's other fields are read on.
#pragma once

#include "api/json_fields.h"
#include "common/material/surface_spec.h"

namespace skyfarm::api {

// Reads a "material" object `f` (the fields above) into s; errors name its fields.
void read_material(const Fields& f, material::SurfaceSpec& s);
// The canonical form of a "material" object.
Json material_json(const material::SurfaceSpec& surface);
// Reads "ground" of the atmosphere object `f` into out.ground_material.
void read_ground(const Fields& f, AtmosphereSpec& out);
// The canonical form of a ground material ({"material": {...}}).
Json ground_json(const material::SurfaceSpec& surface);

}  // namespace skyfarm::api
