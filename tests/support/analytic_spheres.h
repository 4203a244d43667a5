// Spheres in the observer's east-north-up frame as scene objects, by the
// analytic ray-sphere intersection: the test scenes of the path tracer's
// object transport, independent of the production shapes and BVH.
#pragma once

#include <cmath>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>

#include "common/render/scene_objects.h"

namespace skyfarm::testing {

class AnalyticSpheres final : public SceneObjects {
 public:
  struct Sphere {
    glm::dvec3 centre_enu;  // m, from the observer
    double radius_m;
    const material::Surface* surface;
    bool solid = true;  // false: a two-sided sheet (opaque whatever its material)
  };

  AnalyticSpheres(glm::dvec3 observer, std::vector<Sphere> spheres)
      : observer_(observer), spheres_(std::move(spheres)) {}

  std::optional<SurfaceHit> intersect(const Ray& ray, double t_max) const override {
    std::optional<SurfaceHit> best;
    for (const Sphere& s : spheres_) {
      const glm::dvec3 centre = observer_ + s.centre_enu;
      const glm::dvec3 o = ray.o - centre;  // both exact doubles: the difference is accurate
      const double b = glm::dot(o, ray.d);
      const double c = glm::dot(o, o) - s.radius_m * s.radius_m;
      const double disc = b * b - c;
      if (disc < 0.0) continue;
      const double root = std::sqrt(disc);
      for (double t : {-b - root, -b + root}) {
        if (!(t > 1e-9 && t < t_max) || (best && t >= best->t)) continue;
        SurfaceHit h;
        h.t = t;
        h.n = glm::normalize(o + t * ray.d);
        h.p = centre + s.radius_m * h.n;
        h.tangent = std::abs(h.n.z) < 0.999 ? glm::normalize(glm::cross(glm::dvec3(0, 0, 1), h.n)) : glm::dvec3(1, 0, 0);
        h.surface = s.surface;
        h.offset_m = 1e-7 * std::max(1.0, s.radius_m);
        h.solid = s.solid;
        best = h;
        break;
      }
    }
    return best;
  }

  bool occluded(const Ray& ray, double t_max) const override { return intersect(ray, t_max).has_value(); }

 private:
  glm::dvec3 observer_;
  std::vector<Sphere> spheres_;
};

}  // namespace skyfarm::testing
