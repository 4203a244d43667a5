// A ray through a spherically stratified atmosphere (refractive_shells.h),
// bent by refraction.  In spherical symmetry Snell's law is Bouguer's invariant
//   s(r) sin z = k,   s = n(r) r   (z: angle between the ray and the vertical),
// and the ray's polar angle obeys dphi/dr = k / (r sqrt(s^2 - k^2)).  With the
// shells' power law s = s_i (r / r_i)^beta (refractive_shells.h) this
// integrates in closed form: with A(s) = atan2(sqrt((s - k)(s + k)), k),
//   phi(r_b) - phi(r_a) = |A(s_b) - A(s_a)| / |beta|
// along a stretch where r is monotone, and the ray turns (tangent point, or
// top of an arc in a duct, where beta < 0) where s = k.  So the path is exact
// for the shell model: no step size, no drift of k; the only error is the
// shell model's own (its max_refractivity_step).
// Everything is in the ray's plane (radius r, polar angle phi from the
// observer), in doubles, so planet-scale radii keep sub-millimetre precision
// ((r - p) is formed before the square root).
//
// Parameters of trace_refracted_ray:
//   shells             the medium (n = 1 outside the top radius)
//   observer_radius_m  distance of the start point from the planet's centre
//                      (may lie above the top: the ray then travels straight
//                      until it enters)
//   zenith_deg         apparent zenith angle of the ray at the start, [0, 180]
// Outcomes: the ray leaves through the top (kEscaped: its direction is the
// true direction of the source it sees), reaches the ground (kHitGround), or,
// in a duct that does not touch the ground, circles the planet once
// (kTrapped): a bounded loop, never an endless one.  A ray that turns back
// down (a duct: n r decreasing upward) simply continues downward; one that
// dips below its start and turns up again is followed through its tangent
// point.  path holds the exact points at every boundary and turning point; the
// chords between them deviate from the arc by less than (shell thickness)^2 /
// (8 x radius of curvature of the ray, >= ~30 000 km in air).
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "common/atmosphere/refractive_shells.h"

namespace skyfarm {

struct RayVertex {
  double radius_m = 0.0;
  double polar_angle_rad = 0.0;  // from the observer, positive along the ray's horizontal direction
};

struct RefractedRay {
  enum class Outcome { kEscaped, kHitGround, kTrapped };
  Outcome outcome = Outcome::kEscaped;
  std::vector<RayVertex> path;           // start, every boundary crossing and turning point, end
  double invariant_m = 0.0;              // k = n r sin z
  double exit_direction_rad = 0.0;       // direction angle from the observer's zenith, when kEscaped
  double bending_rad = 0.0;              // exit direction minus start zenith, when kEscaped
  double lowest_radius_m = 0.0;          // tangent (or ground) radius of the path
};

RefractedRay trace_refracted_ray(const RefractiveShells& shells, double observer_radius_m, double zenith_deg,
                                 bool record_path = true);
// The same into *result, whose path's storage is reused (the path tracer
// traces a ray per segment and per shadow ray).
void trace_refracted_ray(const RefractiveShells& shells, double observer_radius_m, double zenith_deg,
                         bool record_path, RefractedRay* result);

// The ray's plane in planet-centred coordinates: up is the unit vector from the
// centre to the observer, forward the unit horizontal direction of the ray at
// the observer (perpendicular to up; any such vector for a vertical ray).
glm::dvec3 path_point(const RayVertex& vertex, const glm::dvec3& up, const glm::dvec3& forward);
// Unit direction at polar angle-plus-zenith psi (e.g. exit_direction_rad: the
// escaped ray's direction, the true direction of the source it sees).
glm::dvec3 plane_direction(double psi_rad, const glm::dvec3& up, const glm::dvec3& forward);

}  // namespace skyfarm
