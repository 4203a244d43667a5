// Ray / triangle intersection, watertight (Woop, Benthin & Wald, "Watertight
// Ray/Triangle Intersection", JCGT 2013), in double precision, with the
// conservative t > 0 test of PBR 3rd ed. §3.9.6.
//
// The vertices are carried to a frame where the ray runs along +z from the
// origin (a permutation and a shear that depend on the ray alone), and the
// 2D edge functions decide inside / outside.  Watertight: an edge shared by
// two triangles gets bit-for-bit opposite edge functions in both (computed
// from its two vertices in one canonical order, then negated), so a ray
// through the edge hits at least one of them; a ray through a shared vertex
// likewise.  Edge functions that round to 0 are recomputed in long double.
//
//   t   in (0, t_max), in units of the ray's direction; a hit with t below
//       its own rounding bound is rejected (a ray spawned off the triangle
//       never re-hits it)
//   b   barycentrics: the hit is b0 p0 + b1 p1 + b2 p2
// Both faces hit (no culling).
#pragma once
#include <glm/vec3.hpp>
#include <optional>

#include "common/geometry/ray.h"

namespace skyfarm {

struct TriangleHit {
  double t = 0.0;
  double b0 = 0.0, b1 = 0.0, b2 = 0.0;
};

std::optional<TriangleHit> intersect_triangle(const Ray& ray, const glm::dvec3& p0, const glm::dvec3& p1,
                                              const glm::dvec3& p2, double t_max);

}  // namespace skyfarm
