// The ray-triangle test in double precision that decides every hit of
// TriangleBvh: Moeller-Trumbore, with t, u, v computed in doubles from the
// double vertex positions.  Whatever finds the candidate triangles, this
// function alone says whether and where a ray meets one, so the hit is a pure
// function of the triangle and the ray.
//   origin, dir   the ray (dir need not be unit; t is in units of |dir|)
//   p0, p1, p2    the triangle's vertices
// Returns t (any sign: the caller bounds it), u, v (the weights of p1 and p2;
// p0's is 1 - u - v), or nothing when the ray misses or is parallel to the
// triangle's plane.  Edges count as inside (u, v >= 0, u + v <= 1).
#pragma once

#include <optional>

#include <glm/vec3.hpp>

namespace skyfarm::accel {

struct TriangleHit {
  double t;
  double u;
  double v;
};

std::optional<TriangleHit> intersect_triangle(const glm::dvec3& origin, const glm::dvec3& dir,
                                              const glm::dvec3& p0, const glm::dvec3& p1,
                                              const glm::dvec3& p2);

}  // namespace skyfarm::accel
