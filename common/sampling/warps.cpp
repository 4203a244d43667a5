// Square-to-sphere warps and the orthonormal frame (see warps.h).
#include "common/sampling/warps.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/core/math.h"

namespace skyfarm {
namespace {

// A unit vector from cos(theta), sin(theta) and the azimuth phi.
glm::dvec3 spherical_direction(double sin_theta, double cos_theta, double phi) {
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

}  // namespace

// Uniform sphere (Archimedes' hat-box theorem: z is uniform on [-1, 1]):
//   z = 1 - 2 u.x,  phi = 2 pi u.y,  pdf = 1 / (4 pi).
// sin^2(theta) = (1 - z)(1 + z) = 4 u.x (1 - u.x), exact near both poles.
glm::dvec3 square_to_uniform_sphere(const glm::dvec2& u) {
  const double z = 1.0 - 2.0 * u.x;
  const double sin_theta = 2.0 * safe_sqrt(u.x * (1.0 - u.x));
  return spherical_direction(sin_theta, z, 2.0 * kPi * u.y);
}

double square_to_uniform_sphere_pdf(const glm::dvec3& /*w*/) { return kInv4Pi; }

// Uniform hemisphere: z = 1 - u.x in (0, 1], phi = 2 pi u.y, pdf = 1 / (2 pi).
// sin^2(theta) = (1 - z)(1 + z) = u.x (2 - u.x).
glm::dvec3 square_to_uniform_hemisphere(const glm::dvec2& u) {
  const double z = 1.0 - u.x;
  const double sin_theta = safe_sqrt(u.x * (2.0 - u.x));
  return spherical_direction(sin_theta, z, 2.0 * kPi * u.y);
}

double square_to_uniform_hemisphere_pdf(const glm::dvec3& w) { return w.z > 0.0 ? 0.5 * kInvPi : 0.0; }

// Concentric map (Shirley & Chiu 1997, "A Low Distortion Map Between Disk and
// Square"): the square [-1,1]^2 is cut into four triangles about its diagonals;
// in the triangle where |a| > |b| the radius is a and phi = (pi/4)(b/a), in the
// other r = b and phi = pi/2 - (pi/4)(a/b).  Area-preserving: pdf = 1/pi.
glm::dvec2 square_to_concentric_disk(const glm::dvec2& u) {
  const double a = 2.0 * u.x - 1.0;
  const double b = 2.0 * u.y - 1.0;
  if (a == 0.0 && b == 0.0) return {0.0, 0.0};
  double r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = 0.25 * kPi * (b / a);
  } else {
    r = b;
    phi = 0.5 * kPi - 0.25 * kPi * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

double square_to_concentric_disk_pdf(const glm::dvec2& p) { return p.x * p.x + p.y * p.y <= 1.0 ? kInvPi : 0.0; }

// Cosine-weighted hemisphere by Malley's method: a uniform point of the unit
// disk lifted to the hemisphere, z = sqrt(1 - x^2 - y^2); pdf = cos(theta) / pi.
glm::dvec3 square_to_cosine_hemisphere(const glm::dvec2& u) {
  const glm::dvec2 p = square_to_concentric_disk(u);
  const double z = safe_sqrt(1.0 - p.x * p.x - p.y * p.y);
  return {p.x, p.y, z};
}

double square_to_cosine_hemisphere_pdf(const glm::dvec3& w) { return w.z > 0.0 ? w.z * kInvPi : 0.0; }

// Solid angle of a cone: Omega = 2 pi (1 - cos theta_max) = 4 pi sin^2(theta_max/2)
// (half-angle identity; no cancellation for tiny theta_max).
double uniform_cone_solid_angle(double theta_max) { return 4.0 * kPi * sqr(std::sin(0.5 * theta_max)); }

// Uniform cone: cos(theta) is uniform on [cos theta_max, 1]:
//   1 - cos(theta) = u.x h,  h = 1 - cos(theta_max) = 2 sin^2(theta_max / 2),
//   sin^2(theta) = (1 - cos)(1 + cos) = u.x h (2 - u.x h),
//   phi = 2 pi u.y,  pdf = 1 / Omega = 1 / (2 pi h).
// (pbrt-v4 SampleUniformCone; Mitsuba warp::square_to_uniform_cone.)
glm::dvec3 square_to_uniform_cone(const glm::dvec2& u, double theta_max) {
  return square_to_uniform_cone_of_height(u, uniform_cone_height(theta_max));
}

double uniform_cone_height(double theta_max) { return 2.0 * sqr(std::sin(0.5 * theta_max)); }

glm::dvec3 square_to_uniform_cone_of_height(const glm::dvec2& u, double h) {
  const double one_minus_cos = u.x * h;
  const double cos_theta = 1.0 - one_minus_cos;
  const double sin_theta = safe_sqrt(one_minus_cos * (2.0 - one_minus_cos));
  return spherical_direction(sin_theta, cos_theta, 2.0 * kPi * u.y);
}

// The angle to +z is atan2(|w_xy|, w_z), accurate for tiny angles (unlike acos).
double square_to_uniform_cone_pdf(const glm::dvec3& w, double theta_max) {
  const double theta = std::atan2(std::hypot(w.x, w.y), w.z);
  return theta <= theta_max ? 1.0 / uniform_cone_solid_angle(theta_max) : 0.0;
}

glm::dvec3 square_to_von_mises_fisher(const glm::dvec2& u, double kappa) {
  const double w_z = std::clamp(1.0 + std::log(u.x + (1.0 - u.x) * std::exp(-2.0 * kappa)) / kappa, -1.0, 1.0);
  const double r = std::sqrt(std::max(0.0, (1.0 - w_z) * (1.0 + w_z)));
  const double phi = 2.0 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), w_z};
}

double square_to_von_mises_fisher_pdf(double cos_theta, double kappa) {
  return kappa / (2.0 * kPi * -std::expm1(-2.0 * kappa)) * std::exp(kappa * (cos_theta - 1.0));
}

// Orthonormal basis from a unit vector, Duff, Burgess, Christensen, Hery,
// Kensler, Liani & Villemin (2017), "Building an Orthonormal Basis, Revisited",
// JCGT 6(1), Listing 3:
//   sign = copysign(1, n.z),  a = -1 / (sign + n.z),  b = n.x n.y a,
//   s = (1 + sign n.x^2 a, sign b, -sign n.x),  t = (b, sign + n.y^2 a, -n.y).
// sign + n.z never falls below 1 in magnitude, so no branch near n = -z is needed
// (copysign also gives a valid frame for n.z = -0).
Frame::Frame(const glm::dvec3& n_) : n(n_) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double b = n.x * n.y * a;
  s = {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x};
  t = {b, sign + n.y * n.y * a, -n.y};
}

glm::dvec3 Frame::to_local(const glm::dvec3& v) const { return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)}; }

glm::dvec3 Frame::to_world(const glm::dvec3& v) const { return s * v.x + t * v.y + n * v.z; }

}  // namespace skyfarm
