// What a request says about one object in the scene: its shape, what it is
// made of and where it stands.
//
// Parameters (one element of the request's "objects" array; api/ validates
// and fills it)
//   name       an optional label (status and errors use it)
//   shape      sphere      the unit sphere: radius 1 m before scaling
//              disc        radius 1 m in the object's z = 0 plane, normal +z
//              rectangle   1 m x 1 m in the object's z = 0 plane, normal +z
//              box         1 m x 1 m x 1 m, centred on the origin
//              mesh        a triangle mesh asset, in its own metres
//   asset      mesh only: "sha256:<64 hex>", the id POST /v1/assets answered
//   material   a SurfaceSpec (the ground's "material" object); a Lambertian
//              shorthand in the request becomes a custom diffuse surface
//   placement  translate_m, rotate_deg (yaw, pitch, roll), scale in the
//              observer's local east-north-up frame (geometry/placement.h),
//              whose origin is the ground point directly below the camera
//
// A disc and a rectangle are two-sided; a sphere, a box and a closed mesh
// are solids (a dielectric one is glass: light passes through it).
#pragma once

#include <string>

#include "common/geometry/placement.h"
#include "common/material/surface_spec.h"

namespace skyfarm {

enum class ShapeKind { kSphere, kDisc, kRectangle, kBox, kMesh };

struct ObjectSpec {
  std::string name;
  ShapeKind shape = ShapeKind::kSphere;
  std::string asset;  // mesh only
  material::SurfaceSpec material;
  Placement placement;
};

}  // namespace skyfarm
