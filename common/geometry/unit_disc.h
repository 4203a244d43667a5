// The unit disc x^2 + y^2 <= 1 in the plane z = 0 of its object frame,
// two-sided (a placement scales it into any disc or ellipse).
//
//   intersect  t = -o_z / d_z in (0, t_max); the hit's z is set to 0 exactly
//              (its error bound along the normal is 0: spawn.h still steps
//              the new origin off the plane)
//   n          +z (not flipped towards the ray)
//   uv         (r, phi / 2 pi): polar radius and azimuth from +x towards +y
//   sample     uniform in area by Shirley & Chiu's concentric map of two
//              uniforms in [0, 1) (low distortion for stratified samples):
//              pdf 1 / pi
#pragma once
#include <glm/vec2.hpp>
#include <optional>

#include "common/core/constants.h"
#include "common/geometry/ray.h"
#include "common/geometry/shape_hit.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_unit_disc(const Ray& ray, double t_max);
AreaSample sample_unit_disc(const glm::dvec2& u);
inline constexpr double kUnitDiscArea = kPi;

}  // namespace skyfarm
