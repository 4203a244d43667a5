// The observer's local east-north-up frame and the planet-centred world
// frame of ray.h: the same axes, ENU's origin at world (0, 0, R + altitude).
//
//   to_world(p)  p + (0, 0, R + altitude)
//   to_enu(p)    p - (0, 0, R + altitude): exact (Sterbenz) for every world
//                point within a factor of two of the observer's radius, so a
//                world ray's origin arrives in ENU with no further rounding
//                and objects are intersected in their own frame at the
//                precision of their size, not of the planet's
//
// World coordinates near the observer are ~6.4e6 m, with an ulp of 9.3e-10 m:
// a point stored in world coordinates is only known to ~5e-10 m.
// to_world(hit) adds that rounding to the hit's error bound, so spawn.h's
// offset keeps a ray spawned in world coordinates on the correct side of
// the surface (its offset is then ~1e-9 m instead of ~1e-13 m in ENU).
// Rays from one object to another should still be spawned and carried in
// ENU: with 1e-9 m offsets, a ray bounced deep into the crease where a
// sphere rests on a plane starts under the plane once the gap there is
// below the offset, and leaks; in ENU it does not.
#pragma once
#include <glm/vec3.hpp>

#include "common/geometry/ray.h"
#include "common/geometry/shape_hit.h"

namespace skyfarm {

class EnuFrame {
 public:
  // Throws std::invalid_argument unless observer_radius_m > 0 and finite.
  explicit EnuFrame(double observer_radius_m);

  double observer_radius_m() const { return z0_; }
  glm::dvec3 to_world(const glm::dvec3& enu) const { return {enu.x, enu.y, enu.z + z0_}; }
  glm::dvec3 to_enu(const glm::dvec3& world) const { return {world.x, world.y, world.z - z0_}; }
  Ray to_world(const Ray& enu) const { return {to_world(enu.o), enu.d}; }
  Ray to_enu(const Ray& world) const { return {to_enu(world.o), world.d}; }
  ShapeHit to_world(const ShapeHit& enu_hit) const;

 private:
  double z0_;
};

}  // namespace skyfarm
