// A test-only, explicit simulation of light on a microsurface: rays traced
// against a generated heightfield (microsurface_heightfield.h), bounced by
// each triangle's own BSDF until they leave the surface.  The third, fully
// independent reference of the multiple-bounce models (next to the
// position-free walk and Heitz et al. 2016's walk with heights): it knows
// nothing of Smith's masking, only the geometry.
//
// Parameters
//   surface  the heightfield (not owned; it must outlive the walk).
//   diffuse  Lambertian triangles of albedo 1 (cosine-weighted about the
//            triangle's normal); otherwise perfect mirrors (F = 1).  Neither
//            absorbs, so every ray carries weight 1 and the lobes are counts.
//
// A ray from direction wi starts at a uniformly random point of one period on
// a plane above the highest point, which illuminates the macro surface
// uniformly; its exit direction and the number of bounces are returned.
#pragma once

#include <optional>

#include <glm/vec3.hpp>

#include "common/material/direction_sampling.h"
#include "common/material/random_sequence.h"
#include "tests/common/material/microsurface_heightfield.h"

namespace skyfarm::material::test {

class HeightfieldRandomWalk {
 public:
  HeightfieldRandomWalk(const MicrosurfaceHeightfield& surface, bool diffuse) : surface_(surface), diffuse_(diffuse) {}

  struct Exit {
    glm::dvec3 direction;
    int order = 0;
  };

  // One ray for light arriving from wi (wi.z > 0); nullopt if it was lost
  // (past 1000 bounces, or a ray that neither hit nor escaped).
  std::optional<Exit> trace(const glm::dvec3& wi, RandomSequence& rng) {
    glm::dvec3 origin(rng.next() * surface_.period_x(), rng.next() * surface_.period_y(),
                      surface_.max_height() + 1e-6);
    glm::dvec3 d = -wi;
    for (int order = 0; order <= 1000; ++order) {
      const MicrosurfaceHeightfield::Result r = surface_.intersect(origin, d, &below_);
      if (r.outcome == MicrosurfaceHeightfield::Outcome::escaped) return Exit{d, order};
      if (r.outcome == MicrosurfaceHeightfield::Outcome::lost) return std::nullopt;
      const glm::dvec3& n = r.hit.normal;
      d = diffuse_ ? sample_cosine_around(n, {rng.next(), rng.next()}) : reflect_about(-d, n);
      origin = r.hit.point;
    }
    return std::nullopt;
  }

  // How many times a ray was found below the surface (a tracer error).
  int below_count() const { return below_; }

 private:
  const MicrosurfaceHeightfield& surface_;
  bool diffuse_;
  int below_ = 0;
};

}  // namespace skyfarm::material::test
