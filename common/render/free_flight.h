// Majorant-driven free-flight sampling along a ray through the atmosphere's
// shells (pbrt-v4 SampleT_maj, re-derived for radial shells).
//
// In each shell segment the majorant sigma_maj (per wavelength) is constant.
// Tentative collisions are drawn with the hero wavelength's majorant,
// t += -ln(1 - u) / sigma_maj[0]; at each one the callback receives the point,
// the medium's coefficients there, sigma_maj and T_maj = exp(-sigma_maj dt)
// since the previous collision (per wavelength), and returns whether to go on.
// The returned value is T_maj from the last collision (or the start) to the
// end of the walk; 1 when the callback stopped the walk.  A fresh uniform
// number is drawn for every step (the exponential is memoryless, a rejected
// one is not uniform any more).
#pragma once
#include <cmath>

#include <glm/geometric.hpp>

#include "common/render/atmosphere_medium.h"
#include "common/render/shell_traversal.h"
#include "common/sampling/sampler.h"

namespace skyfarm {

template <class Callback>
SampledSpectrum sample_t_maj(const AtmosphereMedium& medium, const Ray& ray, double t_begin, double t_end,
                             const SampledWavelengths& lambda,
                             const std::array<std::size_t, kWavelengthsPerPath>& bins, Sampler& sampler,
                             MediumPoint& point, Callback&& callback) {
  const double R = medium.atmosphere().planet_radius_m();
  SampledSpectrum T_maj(1.0);
  ShellTraversal walk(ray, R, medium.shell_bottoms(), t_begin, t_end);
  ShellSegment segment;
  while (walk.next(&segment)) {
    const SampledSpectrum sigma_maj = medium.sigma_maj(segment.shell, bins);
    double t = segment.t0;
    // A segment the hero cannot collide in: attenuate by the majorant only.
    if (sigma_maj[0] == 0.0) {
      T_maj *= exp_neg(sigma_maj * (segment.t1 - segment.t0));
      continue;
    }
    while (true) {
      const double u = sampler.next();
      const double dt = -std::log1p(-u) / sigma_maj[0];
      if (t + dt >= segment.t1) {
        T_maj *= exp_neg(sigma_maj * (segment.t1 - t));
        break;
      }
      t += dt;
      T_maj *= exp_neg(sigma_maj * dt);
      const glm::dvec3 p = ray.at(t);
      medium.point(glm::length(p) - R, lambda, &point);
      if (!callback(t, p, sigma_maj, T_maj)) return SampledSpectrum(1.0);
      T_maj = SampledSpectrum(1.0);
    }
  }
  return T_maj;
}

}  // namespace skyfarm
