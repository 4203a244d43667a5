// Every cloud of a scene (layers and volumes) as one grey medium added to the
// air, and the two things a path needs of it:
//
//   sample_collision   the first real collision along a ray, by delta
//                      tracking in each field against its piecewise-constant
//                      majorants (Woodcock; Novak et al. 2018).  The air and
//                      the clouds are independent media: the first collision
//                      of their sum is the nearer of each one's first, so the
//                      path tracer samples the clouds' here and lets the air's
//                      own tracking run up to it.  Grey: the same distance
//                      pdf at every wavelength, so the spectral MIS ratios
//                      are untouched by the clouds.
//   transmittance      an unbiased estimate of exp(-tau_clouds) by ratio
//                      tracking (Novak et al. 2014), with Russian roulette
//                      once the estimate is small: a shadow ray deep in a
//                      thick cloud stops after a few collisions, whatever tau
//                      (in a region of uniform density the majorant is tight
//                      and the first collision's weight is already 0).
//
// Both draw their numbers from the path's sampler, so they are pure functions
// of (job seed, pixel, sample, dimension).
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "common/clouds/cloud_field.h"
#include "common/sampling/sampler.h"

namespace skyfarm {

class SceneClouds {
 public:
  explicit SceneClouds(std::vector<std::shared_ptr<const CloudField>> fields);

  struct Collision {
    double t = 0.0;
    const CloudField* field = nullptr;
  };
  // The first real collision with t_begin < t < t_end, or nothing.
  // `collisions` counts the tentative ones.
  std::optional<Collision> sample_collision(const Ray& ray, double t_begin, double t_end, Sampler& sampler,
                                            std::uint64_t* collisions) const;
  // E[result] = exp(-integral_{t_begin}^{t_end} sigma_t dt), result >= 0.
  double transmittance(const Ray& ray, double t_begin, double t_end, Sampler& sampler,
                       std::uint64_t* collisions) const;
  // The optical depth by the midpoint rule with steps of at most step_m
  // inside each majorant piece (tests, previews).
  double optical_depth(const Ray& ray, double t_begin, double t_end, double step_m) const;

  const std::vector<std::shared_ptr<const CloudField>>& fields() const { return fields_; }
  // The altitude range holding every field.
  double bottom_altitude_m() const { return bottom_m_; }
  double top_altitude_m() const { return top_m_; }

 private:
  std::vector<std::shared_ptr<const CloudField>> fields_;
  double bottom_m_ = 0.0, top_m_ = 0.0;
};

}  // namespace skyfarm
