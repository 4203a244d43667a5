// New rays leaving a surface: the origin is moved off the hit point along
// the geometric normal, to the side the new direction goes, by the hit's
// rounding-error bound projected on the normal, then one more ulp outward
// per component (Pharr, Jakob & Humphreys, PBR 3rd ed., §3.9.5).  The origin
// then lies strictly on the correct side of the true surface, so the new
// ray cannot re-hit it at t > 0 (no acne) nor start behind it (no leak).
// The offset is of the order of the error bound, ~1e-15 of the point's
// coordinates in an object's frame, ~1e-9 m for planet-centred points.
#pragma once
#include <glm/vec3.hpp>

#include "common/geometry/ray.h"
#include "common/geometry/shape_hit.h"

namespace skyfarm {

// p offset by |n|.p_error along n (or -n when w.n < 0), rounded outward.
glm::dvec3 offset_ray_origin(const glm::dvec3& p, const glm::dvec3& p_error, const glm::dvec3& n,
                             const glm::dvec3& w);

// A ray leaving the hit towards w (any length; it is kept as given).
Ray spawn_ray(const ShapeHit& hit, const glm::dvec3& w);

}  // namespace skyfarm
