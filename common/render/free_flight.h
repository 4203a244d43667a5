// Majorant-driven free-flight sampling along a ray through the atmosphere's
// shells (pbrt-v4 SampleT_maj, re-derived for radial shells).
//
// In each shell segment the majorant sigma_maj (per wavelength) is constant,
// so the hero wavelength's majorant optical depth grows piecewise linearly
// along the ray.  A tentative collision happens where it reaches a target
// tau* = -ln(1 - u) drawn once per flight (regular tracking): segments are
// crossed by subtracting their optical depth from tau*, with no random number
// or exponential per segment.  At each collision the callback receives the
// point, sigma_maj there and T_maj = exp(-tau_maj) per wavelength since the
// previous collision (the medium's coefficients are in `point`), and returns
// whether to go on; then a fresh tau* is drawn.  The returned value is T_maj
// from the last collision (or the start) to the end of the walk; 1 when the
// callback stopped the walk.  `majorant_scale` >= 1 inflates the majorants
// (still bounds, so still unbiased) to place more tentative collisions on a
// ray, e.g. where each one gathers sunlight (volume_path_integrator.cpp).
//
// `forced_tau` > 0 (the hero's scaled majorant optical depth of the whole
// walk) forces the first tentative collision: its tau* is drawn from the
// exponential truncated to [0, forced_tau), pdf e^-tau / (1 - e^-forced_tau),
// so the walk always collides at least once; the caller owns the weight
// 1 - e^-forced_tau and the walk's collision-free share e^-forced_tau
// (forced collisions, e.g. Mitsuba's "forced scattering" of camera rays).
#pragma once
#include <cmath>
#include <utility>

#include <glm/geometric.hpp>

#include "common/render/atmosphere_medium.h"
#include "common/render/path_majorants.h"
#include "common/render/shell_traversal.h"
#include "common/sampling/sampler.h"

namespace skyfarm {

//
// sample_t_maj_along does the same along any walk of the ray's shell segments
// (a ShellTraversal, or the replay of a RecordedShellWalk when the segments
// were already walked for majorant_optical_depth), with the majorants of the
// path's wavelengths from `majorants` (PathMajorants: path_majorants.h).
// `ray` is anything with at(t): a Ray, or a bent path's walk (bent_path.h),
// whose at(t) lies on the chord it walks.
template <class Walk, class Majorants, class Callback, class Line>
SampledSpectrum sample_t_maj_along(Walk& walk, const Majorants& majorants, const AtmosphereMedium& medium,
                                   const Line& ray, const PathCoefficients& path, Sampler& sampler, MediumPoint& point,
                                   Callback&& callback, double majorant_scale = 1.0, double forced_tau = 0.0) {
  const double R = medium.atmosphere().planet_radius_m();
  SampledSpectrum tau_maj(0.0);  // majorant optical depth since the last collision
  double tau_target = forced_tau > 0.0
                          // Kept a hair inside the walk so round-off cannot lose the collision.
                          ? std::min(-std::log1p(sampler.next() * std::expm1(-forced_tau)), forced_tau * (1.0 - 1e-12))
                          : -std::log1p(-sampler.next());
  ShellSegment segment;
  while (walk.next(&segment)) {
    const SampledSpectrum sigma_maj = majorants.sigma_maj(segment.shell) * majorant_scale;
    double t = segment.t0;
    while (true) {
      const double tau_rest = sigma_maj[0] * (segment.t1 - t);
      if (tau_target >= tau_rest) {  // no collision in the rest of this segment
        tau_target -= tau_rest;
        tau_maj += sigma_maj * (segment.t1 - t);
        break;
      }
      const double dt = tau_target / sigma_maj[0];
      t += dt;
      tau_maj += sigma_maj * dt;
      const glm::dvec3 p = ray.at(t);
      medium.point(glm::length(p) - R, path, &point);
      if (!callback(t, p, sigma_maj, exp_neg(tau_maj))) return SampledSpectrum(1.0);
      tau_maj = SampledSpectrum(0.0);
      tau_target = -std::log1p(-sampler.next());
    }
  }
  return exp_neg(tau_maj);
}

template <class Callback>
SampledSpectrum sample_t_maj(const AtmosphereMedium& medium, const ShellMajorants& shells, const Ray& ray,
                             double t_begin, double t_end,
                             const PathCoefficients& path, Sampler& sampler, MediumPoint& point,
                             Callback&& callback, double majorant_scale = 1.0, double forced_tau = 0.0) {
  ShellTraversal walk(ray, medium.atmosphere().planet_radius_m(), shells.bottoms, t_begin, t_end);
  return sample_t_maj_along(walk, PathMajorants(shells, path.bins), medium, ray, path, sampler, point,
                            std::forward<Callback>(callback), majorant_scale, forced_tau);
}

// The majorant optical depth of [t_begin, t_end] at each of the path's
// wavelengths: the expected number of tentative collisions there.
// Along any walk of shell segments, any majorants (see sample_t_maj_along).
template <class Walk, class Majorants>
SampledSpectrum majorant_optical_depth_along(Walk& walk, const Majorants& majorants) {
  ShellSegment segment;
  // tau += sigma_maj * (t1 - t0), element by element, summed in plain locals
  // so that the compiler keeps them in registers (a SampledSpectrum return
  // slot went through memory at every segment); the same operations in the
  // same order.
  double sum[kWavelengthsPerPath] = {};
  while (walk.next(&segment)) {
    const SampledSpectrum m = majorants.sigma_maj(segment.shell);
    const double dt = segment.t1 - segment.t0;
    for (int i = 0; i < kWavelengthsPerPath; ++i) sum[i] += m[i] * dt;
  }
  SampledSpectrum tau;
  for (int i = 0; i < kWavelengthsPerPath; ++i) tau[i] = sum[i];
  return tau;
}

inline SampledSpectrum majorant_optical_depth(const AtmosphereMedium& medium, const ShellMajorants& shells,
                                              const Ray& ray, double t_begin, double t_end,
                                              const std::array<std::size_t, kWavelengthsPerPath>& bins) {
  ShellTraversal walk(ray, medium.atmosphere().planet_radius_m(), shells.bottoms, t_begin, t_end);
  return majorant_optical_depth_along(walk, PathMajorants(shells, bins));
}

}  // namespace skyfarm
