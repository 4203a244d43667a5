// The unit cube [-0.5, 0.5]^3 of its object frame, a closed solid (a
// placement scales it into any box).
//
//   intersect  slab test (Kay & Kajiya): the first hit with t in (0, t_max),
//              entering from outside or leaving from inside; faces include
//              their edges, so rays at an edge or a corner hit; the hit's
//              coordinate on its face's axis is set to +-0.5 exactly
//   n          the face's outward axis
//   primitive  the face: 0..5 = -x, +x, -y, +y, -z, +z
//   uv         the two other coordinates + 0.5, in axis order (for +-x: y, z)
#pragma once
#include <optional>

#include "common/geometry/ray.h"
#include "common/geometry/shape_hit.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_unit_box(const Ray& ray, double t_max);

}  // namespace skyfarm
