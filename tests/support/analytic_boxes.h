// Axis-aligned boxes in the observer's east-north-up frame as scene
// objects (closed solids, outward normals), by the slab method: the test
// scenes of light through flat glass, independent of the production shapes
// and BVH.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>

#include "common/render/scene_objects.h"

namespace skyfarm::testing {

class AnalyticBoxes final : public SceneObjects {
 public:
  struct Box {
    glm::dvec3 centre_enu;  // m, from the observer
    glm::dvec3 half_size_m;
    const material::Surface* surface;
  };

  AnalyticBoxes(glm::dvec3 observer, std::vector<Box> boxes) : observer_(observer), boxes_(std::move(boxes)) {}

  std::optional<SurfaceHit> intersect(const Ray& ray, double t_max) const override {
    std::optional<SurfaceHit> best;
    for (const Box& b : boxes_) {
      const glm::dvec3 o = ray.o - (observer_ + b.centre_enu);  // in the box's frame
      double t_near = -1e300, t_far = 1e300;
      int axis_near = 0, axis_far = 0;
      bool miss = false;
      for (int a = 0; a < 3; ++a) {
        if (ray.d[a] == 0.0) {
          if (std::abs(o[a]) > b.half_size_m[a]) miss = true;
          continue;
        }
        double t0 = (-b.half_size_m[a] - o[a]) / ray.d[a], t1 = (b.half_size_m[a] - o[a]) / ray.d[a];
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > t_near) t_near = t0, axis_near = a;
        if (t1 < t_far) t_far = t1, axis_far = a;
      }
      if (miss || t_near > t_far) continue;
      // The entry if it is ahead, else the exit (the ray starts inside).
      const bool entering = t_near > 1e-9;
      const double t = entering ? t_near : t_far;
      const int axis = entering ? axis_near : axis_far;
      if (!(t > 1e-9 && t < t_max) || (best && t >= best->t)) continue;
      SurfaceHit h;
      h.t = t;
      h.p = ray.o + t * ray.d;
      h.n = glm::dvec3(0.0);
      h.n[axis] = (o[axis] + t * ray.d[axis]) > 0.0 ? 1.0 : -1.0;
      h.tangent = axis == 0 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
      h.surface = b.surface;
      h.offset_m = 1e-7 * std::max(1.0, glm::length(b.half_size_m));
      h.solid = true;
      best = h;
    }
    return best;
  }

  bool occluded(const Ray& ray, double t_max) const override { return intersect(ray, t_max).has_value(); }

 private:
  glm::dvec3 observer_;
  std::vector<Box> boxes_;
};

}  // namespace skyfarm::testing
