// The unit sphere centred on the origin, in its object frame (a placement
// scales it into any sphere or ellipsoid).
//
//   intersect  the first hit with t in (0, t_max), from outside or inside;
//              the ray's direction need not be unit (t in its units); the
//              roots come from sphere_intersection.h's cancellation-free
//              quadratic, the point is reprojected to |p| = 1 with error
//              gamma(5)|p| (PBR 3rd ed., §3.9.4)
//   n          p, outward
//   uv         (phi / 2 pi, theta / pi): phi the azimuth from +x towards +y
//              in [0, 2 pi), theta the angle from +z
//   sample     uniform in area from two uniforms in [0, 1): pdf 1 / (4 pi)
#pragma once
#include <glm/vec2.hpp>
#include <optional>

#include "common/core/constants.h"
#include "common/geometry/ray.h"
#include "common/geometry/shape_hit.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_unit_sphere(const Ray& ray, double t_max);
AreaSample sample_unit_sphere(const glm::dvec2& u);
inline constexpr double kUnitSphereArea = 4.0 * kPi;

}  // namespace skyfarm
