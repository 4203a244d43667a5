#include "common/geometry/sphere_intersection.h"

#include <cmath>
#include <glm/geometric.hpp>

#include "common/core/math.h"

namespace skyfarm {

RadialRay radial_ray(const Ray& ray) {
  RadialRay k;
  k.r = glm::length(ray.o);
  k.b = glm::dot(ray.o, ray.d);
  // Closest approach of the line to the centre.
  k.l = glm::length(ray.o - k.b * ray.d);
  return k;
}

SphereHit intersect_sphere(const Ray& ray, double radius) { return intersect_sphere(radial_ray(ray), radius); }

SphereHit intersect_sphere(const RadialRay& ray, double radius) {
  const double r = ray.r, b = ray.b, l = ray.l;
  // The discriminant b^2 - c.
  const double D = (radius - l) * (radius + l);
  if (D < 0.0) return {};
  const double c = (r - radius) * (r + radius);
  const double sqrt_D = std::sqrt(D);
  const double q = -(b + std::copysign(sqrt_D, b));
  SphereHit hit;
  hit.hit = true;
  if (q == 0.0) {  // b = 0 and D = 0: the origin touches the sphere tangentially
    hit.t_near = hit.t_far = 0.0;
    return hit;
  }
  const double t0 = q, t1 = c / q;
  hit.t_near = std::min(t0, t1);
  hit.t_far = std::max(t0, t1);
  return hit;
}

double distance_to_sphere(const Ray& ray, double radius) {
  const SphereHit h = intersect_sphere(ray, radius);
  if (!h.hit) return -1.0;
  if (h.t_near > 0.0) return h.t_near;
  if (h.t_far > 0.0) return h.t_far;
  return -1.0;
}

double ground_distance(const Ray& ray, double radius) { return ground_distance(radial_ray(ray), radius); }

double ground_distance(const RadialRay& ray, double radius) {
  if (ray.r <= radius) return ray.b < 0.0 ? 0.0 : -1.0;
  const SphereHit h = intersect_sphere(ray, radius);
  return (h.hit && h.t_near >= 0.0) ? h.t_near : -1.0;
}

double altitude_above(const glm::dvec3& p, double radius) { return glm::length(p) - radius; }

double horizon_cosine(double r, double R) { return -safe_sqrt((r - R) * (r + R)) / r; }

}  // namespace skyfarm
