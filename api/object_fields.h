// "objects": things placed in the scene, read and written.
//
//   "objects": [{
//     "name": "chrome ball",          optional label, 1 to 64 characters
//     "shape": "sphere",              sphere | disc | rectangle | box | mesh
//     "asset": "sha256:<64 hex>",     mesh only: the id POST /v1/assets answered
//     "material": {...},              the ground's material object (surface_fields.h), or
//     "albedo": 0.18,                 its Lambertian shorthand, in [0, 1]; neither: 0.5
//     "translate_m": [e, n, u],       metres, |each| <= 200000; default [0, 0, 0]
//     "rotate_deg": [yaw, pitch, roll],  degrees in [-360, 360]; default [0, 0, 0]
//     "scale": s or [sx, sy, sz]}]    each |s| in [1e-6, 1e6] (negative mirrors); default 1
//
// The frame is the observer's local east-north-up frame with its origin on
// the ground directly below the camera (common/objects/object_spec.h has the
// shapes' sizes, geometry/placement.h the angles).  At most kMaxObjects.
// The path tracer alone renders objects: with "method": "lut" they are an
// error.  The canonical form writes "objects" only when there are some, so
// requests without them keep their text; the shorthand stays a shorthand.
#pragma once

#include <vector>

#include "api/json_fields.h"
#include "common/objects/object_spec.h"

namespace skyfarm::api {

inline constexpr std::size_t kMaxObjects = 1000;
inline constexpr double kMaxObjectDistance_m = 200000.0;
inline constexpr double kDefaultObjectAlbedo = 0.5;

// Reads "objects" of the request object `top` into out.
void read_objects(const Fields& top, std::vector<ObjectSpec>& out);
// The canonical "objects" array.
Json objects_json(const std::vector<ObjectSpec>& objects);

// The placement fields "translate_m", "rotate_deg", "scale" of the object `f`
// (rules above; absent ones leave `out`), and their canonical members added to `out`.
// Cloud volumes share them (api/cloud_fields.h).
void read_placement(const Fields& f, Placement& out);
void placement_json(const Placement& placement, Json& out);

// The custom diffuse surface the shorthand "albedo": a stands for, and
// whether a surface is one (its canonical form is then the shorthand).
material::SurfaceSpec lambertian_surface(double albedo);
bool is_lambertian_shorthand(const material::SurfaceSpec& surface);

}  // namespace skyfarm::api
