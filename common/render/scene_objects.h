// What the path tracer needs of the objects in a scene (spheres, boxes,
// meshes placed near the observer): the closest surface a ray meets, and
// whether anything blocks a shadow ray.  Rays are planet-centred (origins
// ~6.4e6 m from the centre); an implementation intersects in a frame near
// the objects so that its precision does not depend on the planet.
//
// A scene without objects has none of this (Scene::objects() is null) and
// its paths take exactly the code they always took.
#pragma once

#include <optional>

#include <glm/vec3.hpp>

#include "common/geometry/ray.h"
#include "common/material/surface.h"

namespace skyfarm {

struct SurfaceHit {
  double t = 0.0;             // along the ray, m
  glm::dvec3 p{0.0};          // the hit point, planet-centred, m
  glm::dvec3 n{0.0, 0.0, 1.0};  // the unit geometric normal (outward; the path tracer picks the side)
  glm::dvec3 tangent{1.0, 0.0, 0.0};  // a unit tangent: the anisotropic roughness_x axis
  const material::Surface* surface = nullptr;  // the object's material (never null)
  double offset_m = 1e-6;     // how far rays leaving the hit start off the surface
  bool solid = false;         // the object encloses a volume (n points out of it); else a two-sided sheet
};

class SceneObjects {
 public:
  virtual ~SceneObjects() = default;
  // The closest hit with 0 < t < t_max, or nothing.
  virtual std::optional<SurfaceHit> intersect(const Ray& ray, double t_max) const = 0;
  // Whether any surface lies on the ray with 0 < t < t_max.
  virtual bool occluded(const Ray& ray, double t_max) const = 0;
};

}  // namespace skyfarm
