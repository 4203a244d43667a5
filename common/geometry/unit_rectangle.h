// The unit square [-0.5, 0.5]^2 in the plane z = 0 of its object frame,
// two-sided (a placement scales it into any rectangle or parallelogram).
//
//   intersect  as plane_hit.h, inside |x| <= 0.5 and |y| <= 0.5 (edges
//              included, so two rectangles sharing an edge leave no gap)
//   n          +z (not flipped towards the ray)
//   uv         (x + 0.5, y + 0.5)
//   sample     uniform in area: p = (u_x - 0.5, u_y - 0.5, 0), pdf 1
#pragma once
#include <glm/vec2.hpp>
#include <optional>

#include "common/geometry/ray.h"
#include "common/geometry/shape_hit.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_unit_rectangle(const Ray& ray, double t_max);
AreaSample sample_unit_rectangle(const glm::dvec2& u);
inline constexpr double kUnitRectangleArea = 1.0;

}  // namespace skyfarm
