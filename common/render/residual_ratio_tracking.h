// Residual ratio tracking of transmittance (Novák, Selle & Jarosz 2014,
// "Residual ratio tracking for estimating attenuation in participating
// media", §4), for shadow rays and the sunlit-segment estimator.
//
// With a control extinction sigma_c known in closed form (piecewise constant
// per fine shell and wavelength bin: AtmosphereMedium::control_shells) and
// the residual sigma_r = sigma_t - sigma_c,
//   T = exp(-tau_c) * E[ prod_k (mu_r(x_k) - sigma_r(x_k)) / mu_r(x_k) ],
// with x_k the points of a Poisson process of rate mu_r = sigma_maj - sigma_c
// (the residual majorant, AtmosphereMedium::residual_shells).  Since sigma_c
// is a lower bound of sigma_t, every factor is in [0, 1].  The relative
// variance is exp(int sigma_r^2 / mu_r dt) - 1 <= exp(int mu_r dt) - 1,
// against exp(int sigma_t^2 / sigma_maj dt) - 1 for plain ratio tracking:
// a fine shell holds the density within a few per cent (200 m shells near the
// ground, 10 % of the altitude above), so a grazing shadow ray of optical
// depth 20 gets a relative variance of order 0.1 instead of e^5 with
// majorants x4, and about 20 times fewer collisions.
//
// Spectral: the collisions follow the hero wavelength's residual majorant;
// for wavelength i the estimate is
//   T_i = exp(-tau_c,i) exp(-int (mu_i - mu_0)) prod_k (mu_i - sigma_r,i) / mu_0,
// unbiased at every wavelength where mu_0 > 0 (the control is shaved by 1e-9
// relative, so mu_0 > 0 wherever the hero sees any extinction).  r_l holds,
// per wavelength, the pdf of the collision pattern had it been the hero over
// the hero's pdf (spectral MIS, pbrt-v4 SampleLd); r_u = T before roulette.
//
//   radial     the ray's constants (radial_ray(ray)), shared with the caller's
//              ground and top intersections
//   roulette   Russian roulette (q = 0.75) once the MIS-weighted estimate
//              T / avg(r_l + r_u) falls below 0.05 (shadow rays)
#pragma once
#include <glm/geometric.hpp>

#include "common/geometry/sphere_intersection.h"
#include "common/render/atmosphere_medium.h"
#include "common/render/path_majorants.h"
#include "common/render/shell_traversal.h"
#include "common/sampling/sampler.h"

namespace skyfarm {

struct TrackedTransmittance {
  SampledSpectrum T{1.0}, r_l{1.0}, r_u{1.0};
};

inline TrackedTransmittance residual_ratio_tracking(const AtmosphereMedium& medium, const Ray& ray,
                                                    const RadialRay& radial, double t_begin, double t_end,
                                                    const PathCoefficients& path, Sampler& sampler,
                                                    std::uint64_t* collisions, bool roulette) {
  const ShellMajorants& residual = medium.residual_shells();
  // The path's columns of both tables, found once (not per shell crossed).
  const PathMajorants residual_of(residual, path.bins), control_of(medium.control_shells(), path.bins);
  const double R = medium.atmosphere().planet_radius_m();
  TrackedTransmittance out;
  SampledSpectrum tau_r(0.0), tau_c(0.0);  // since the last collision
  MediumPoint mp;
  double tau_target = -std::log1p(-sampler.next());
  ShellTraversal walk(ray, radial, R, residual.bottoms, t_begin, t_end);
  ShellSegment segment;
  while (walk.next(&segment)) {
    const double mu_r0 = residual_of.sigma_maj0(segment.shell);
    double t = segment.t0;
    while (true) {
      const double tau_rest = mu_r0 * (segment.t1 - t);
      if (tau_target >= tau_rest) {  // no collision in the rest of this segment
        tau_target -= tau_rest;
        residual_of.add_optical_depth(segment.shell, segment.t1 - t, &tau_r);
        control_of.add_optical_depth(segment.shell, segment.t1 - t, &tau_c);
        break;
      }
      const SampledSpectrum mu_r = residual_of.sigma_maj(segment.shell);
      const SampledSpectrum sigma_c = control_of.sigma_maj(segment.shell);
      const double dt = tau_target / mu_r0;
      t += dt;
      tau_r += mu_r * dt;
      tau_c += sigma_c * dt;
      ++*collisions;
      medium.point(glm::length(ray.at(t)) - R, path, &mp);
      // (mu_r - sigma_r) = sigma_c + mu_r - sigma_t, >= 0 up to round-off.
      const SampledSpectrum sigma_n = clamp_zero(sigma_c + mu_r - mp.sigma_a - mp.sigma_s);
      const SampledSpectrum T_r = exp_neg(tau_r);
      const double pdf = T_r[0] * mu_r[0];
      const SampledSpectrum T_c = exp_neg(tau_c);
      out.T *= T_r * T_c * sigma_n * (1.0 / pdf);
      out.r_u *= T_r * T_c * sigma_n * (1.0 / pdf);
      out.r_l *= T_r * mu_r * (1.0 / pdf);
      tau_r = SampledSpectrum(0.0);
      tau_c = SampledSpectrum(0.0);
      if (roulette && (out.T * (1.0 / (out.r_l + out.r_u).average())).max() < 0.05) {
        const double q = 0.75;
        if (sampler.next() < q) {
          out.T = SampledSpectrum(0.0);
          return out;
        }
        out.T *= 1.0 / (1.0 - q);
      }
      if (out.T.is_zero()) return out;
      tau_target = -std::log1p(-sampler.next());
    }
  }
  const SampledSpectrum T_r = exp_neg(tau_r);
  const SampledSpectrum ratio = T_r * (1.0 / T_r[0]);
  const SampledSpectrum T_c = exp_neg(tau_c);
  out.T *= ratio * T_c;
  out.r_u *= ratio * T_c;
  out.r_l *= ratio;
  return out;
}

}  // namespace skyfarm
