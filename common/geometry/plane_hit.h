// The hit of a ray with the plane z = 0 of an object frame, shared by the
// disc, the rectangle and the box's faces (after a swap of axes).
//
//   t        -o_z / d_z, accepted in (0, t_max); a ray parallel to the
//            plane (d_z = 0) or starting on it (o_z = 0) misses
//   p        o + t d with p_z set to 0 exactly
//   p_error  x, y: gamma(3)(|o| + |t d|); z: 0
//   n        +z
#pragma once
#include <optional>

#include "common/geometry/ray.h"
#include "common/geometry/shape_hit.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_plane_z0(const Ray& ray, double t_max);

}  // namespace skyfarm
