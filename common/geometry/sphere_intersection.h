// Ray / sphere intersection at planetary scale, in double precision with a
// numerically stable quadratic.
//
// For a ray o + t d (|d| = 1) and a sphere of radius R centred at the origin:
//   t^2 + 2 b t + c = 0,  b = o.d,  c = |o|^2 - R^2 = (r - R)(r + R), r = |o|.
// Two forms keep every digit:
//   * c is formed as (r - R)(r + R): for a camera 1 m above a 6 371 km planet,
//     |o|^2 - R^2 would cancel ~13 of 16 digits, (r - R) cancels none;
//   * the discriminant b^2 - c is formed as (R - l)(R + l), where l = |o - b d|
//     is the ray's distance of closest approach to the centre (Hearn & Baker;
//     Haines et al., Ray Tracing Gems ch. 7): no cancellation for rays that
//     graze the sphere, so hit / miss is decided by l < R alone, a monotone
//     function of the ray's direction.
// Roots: q = -(b + sign(b) sqrt(D)), t0 = q, t1 = c / q (Press et al., Numerical
// Recipes §5.6), sorted.
#pragma once
#include "common/geometry/ray.h"

namespace skyfarm {

// The ray's constants with respect to the centre, shared by every sphere
// (ground, top, shell boundaries) it is tested against: r = |o|, b = o.d and
// l = |o - b d|.  The functions below taking a RadialRay give the same bits
// as those taking the Ray, without recomputing them.
struct RadialRay {
  double r = 0.0, b = 0.0, l = 0.0;
};
RadialRay radial_ray(const Ray& ray);

struct SphereHit {
  bool hit = false;
  double t_near = 0.0;  // smaller root (may be < 0: behind the origin)
  double t_far = 0.0;   // larger root
};

// Both intersections of the ray's line with the sphere of `radius`.
SphereHit intersect_sphere(const Ray& ray, double radius);
SphereHit intersect_sphere(const RadialRay& ray, double radius);

// Distance along the ray to where it first enters the sphere's solid ball
// from outside, or leaves it from inside: the smallest root > 0; returns a
// negative number when there is none.
double distance_to_sphere(const Ray& ray, double radius);

// Distance along the ray to the ground, a sphere of `radius` seen from above:
// the near root when the origin is above it; 0 when the origin is on (or,
// by round-off, just below) the surface and the ray points into it; -1 when
// the ray never meets it.  A camera standing on the ground (altitude 0) thus
// sees the ground at its feet instead of the far side of the planet.
double ground_distance(const Ray& ray, double radius);
double ground_distance(const RadialRay& ray, double radius);

// Altitude of a point above a sphere of `radius`: |p| - radius.
double altitude_above(const glm::dvec3& p, double radius);

// Cosine of the zenith angle at which a ray leaving radius r grazes a sphere
// of radius R < r: mu_h = -sqrt(1 - (R/r)^2) = -sqrt((r - R)(r + R)) / r.
double horizon_cosine(double r, double R);

}  // namespace skyfarm
