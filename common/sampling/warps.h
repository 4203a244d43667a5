// Square-to-sphere warps: maps from uniform numbers u in [0,1)^2 to directions
// with a known density, and the orthonormal frame that carries a local
// direction (about +z) to the world.
//
// Every warp comes as a pair (Mitsuba's `warp` naming):
//   square_to_X(u, ...)         -> unit vector (or disk point), u in [0,1)^2
//   square_to_X_pdf(w, ...)     -> its density in 1/sr (1/m^2 for the disk)
// The density of a direction the warp cannot produce is 0.
//
// Parameters
//   u          glm::dvec2, both components in [0, 1).  u.x drives the polar
//              coordinate (cos theta or the disk radius), u.y the azimuth phi.
//   w          glm::dvec3, a unit vector in the warp's local frame (+z = pole).
//   theta_max  double, half-angle of a cone in radians, 0 < theta_max <= pi
//              (the sun disk is 0.2666 deg = 4.653e-3 rad).  Its solid angle
//              2 pi (1 - cos theta_max) is evaluated as 4 pi sin^2(theta_max/2),
//              which keeps full relative precision for tiny cones.
//
// Frame(n): a right-handed orthonormal basis (s, t, n) from a unit vector n,
// branch-free except for the sign of n.z (Duff et al. 2017).
//
// All arithmetic in double precision, no fast-math: the same bits on every
// worker.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace skyfarm {

// --- Uniform sphere -----------------------------------------------------
glm::dvec3 square_to_uniform_sphere(const glm::dvec2& u);
double square_to_uniform_sphere_pdf(const glm::dvec3& w);

// --- Uniform hemisphere about +z (z > 0) --------------------------------
glm::dvec3 square_to_uniform_hemisphere(const glm::dvec2& u);
double square_to_uniform_hemisphere_pdf(const glm::dvec3& w);

// --- Concentric disk (Shirley & Chiu 1997): unit square -> unit disk ----
glm::dvec2 square_to_concentric_disk(const glm::dvec2& u);
double square_to_concentric_disk_pdf(const glm::dvec2& p);

// --- Cosine-weighted hemisphere about +z (Malley's method) --------------
glm::dvec3 square_to_cosine_hemisphere(const glm::dvec2& u);
double square_to_cosine_hemisphere_pdf(const glm::dvec3& w);

// --- Uniform cone of half-angle theta_max about +z ----------------------
// Solid angle of the cone, 4 pi sin^2(theta_max / 2) sr.
double uniform_cone_solid_angle(double theta_max);
glm::dvec3 square_to_uniform_cone(const glm::dvec2& u, double theta_max);
// The same cone given by h = 1 - cos(theta_max) = uniform_cone_height(theta_max),
// for callers that sample one cone many times (the sun disk): no sine per sample.
double uniform_cone_height(double theta_max);
glm::dvec3 square_to_uniform_cone_of_height(const glm::dvec2& u, double h);
// 1 / solid angle inside the cone (angle to +z <= theta_max), 0 outside.
double square_to_uniform_cone_pdf(const glm::dvec3& w, double theta_max);

// --- Von Mises-Fisher lobe about +z, concentration kappa > 0 ------------
//   pdf(w) = kappa / (2 pi (1 - e^{-2 kappa})) e^{kappa (w.z - 1)},
// sampled exactly (Jakob 2012, "Numerically stable sampling of the von
// Mises-Fisher distribution on S^2"): w.z = 1 + ln(u + (1 - u) e^{-2 kappa}) / kappa.
glm::dvec3 square_to_von_mises_fisher(const glm::dvec2& u, double kappa);
double square_to_von_mises_fisher_pdf(double cos_theta, double kappa);

// --- Orthonormal frame ---------------------------------------------------
// (s, t, n) right-handed and orthonormal; to_world(0,0,1) == n.
struct Frame {
  glm::dvec3 s{1.0, 0.0, 0.0};
  glm::dvec3 t{0.0, 1.0, 0.0};
  glm::dvec3 n{0.0, 0.0, 1.0};

  Frame() = default;
  // n must be a unit vector.
  explicit Frame(const glm::dvec3& n);

  glm::dvec3 to_local(const glm::dvec3& v) const;
  glm::dvec3 to_world(const glm::dvec3& v) const;
};

}  // namespace skyfarm
