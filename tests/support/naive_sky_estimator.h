// Test support: a deliberately naive estimator of the sky's radiance at ONE
// wavelength, an oracle for the production path tracer
// (VolumePathIntegrator) that shares none of its variance-reduction devices.
//
// What it does, and what it does not share with the production estimator:
//   coefficients     the atmosphere's own sigma_s / sigma_a per constituent
//                    (Constituent::sigma_s, sigma_a), tabulated once on an
//                    altitude grid of kTableStepM and interpolated linearly
//                    (relative error ~ step^2 / (8 H^2) ~ 2e-6 for the
//                    aerosol's H ~ 1.2 km); no majorants, no shells.
//   free flight      analog: tau* = -ln(1 - u) and the ray marched in small
//                    steps (altitude change <= 20 m + 1 % of the altitude,
//                    length <= 5 km), sigma_t taken at each step's midpoint
//                    and the distance inverted exactly within the step.
//                    Midpoint-rule error ~ (dh / H)^2 / 24, below 1e-4.
//   absorption       analog: at a collision the path scatters with
//                    probability sigma_s / sigma_t and ends otherwise; at the
//                    ground it goes on with probability rho.
//   scattering       the constituent drawn with probability sigma_s,i / sigma_s,
//                    the direction from its phase function (phase_at(lambda)).
//   ground           Lambertian, the next direction cosine-distributed
//                    (its own warp, not the renderer's).
//   sun              next-event estimation at every real scattering vertex
//                    and ground hit, a direction drawn uniformly in the disk
//                    (its own cone warp), the transmittance to the top by the
//                    same deterministic step quadrature, 0 when the ray meets
//                    the planet.  Phase-sampled directions that happen to
//                    fall in the disk are NOT counted (no MIS).  Counting
//                    the sun only on such hits would be unbiased too, but
//                    the disk is 6.8e-5 sr: ~1 path in 10^5 would score.
//   randomness       std::mt19937_64, seeded by the caller; no Sampler.
//   environment      Scene::environment_radiance is ignored (0 in real skies).
//
// Also: the first-order (single-scattering) radiance by deterministic
// quadrature along the view ray, sun transmittance by quadrature and the
// planet's shadow included, for a point sun (the disk's average over its
// 0.27 deg is not integrated: use a scene with angular radius 0).
#pragma once
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "common/atmosphere/phase_function.h"
#include "common/geometry/ray.h"
#include "common/render/scene.h"

namespace skyfarm::testing {

struct NaiveEstimate {
  double mean = 0.0;
  double standard_error = 0.0;
  std::uint64_t paths = 0;
  double seconds = 0.0;
};

// The mean of `paths` calls of sample(i), its standard error and the time taken.
template <class Sample>
NaiveEstimate estimate_mean(int paths, Sample&& sample) {
  const auto start = std::chrono::steady_clock::now();
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < paths; ++i) {
    const double x = sample(i);
    sum += x;
    sum2 += x * x;
  }
  NaiveEstimate e;
  e.paths = static_cast<std::uint64_t>(paths);
  e.mean = sum / paths;
  e.standard_error = std::sqrt(std::max(0.0, sum2 / paths - e.mean * e.mean) / (paths - 1.0));
  e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return e;
}

class NaiveSkyEstimator {
 public:
  static constexpr double kTableStepM = 5.0;

  NaiveSkyEstimator(const Scene& scene, double lambda_nm);

  // Optical depth along `ray` (planet-centred) up to t_end, or to the top of
  // the atmosphere if that is nearer; stops at the ground.
  double optical_depth(const Ray& ray, double t_end) const;
  // Transmittance from p towards the sun direction w (unit): 0 when the ray
  // meets the planet, else exp(-optical depth to the top).
  double sun_transmittance(const glm::dvec3& p, const glm::dvec3& w) const;

  // One path's estimate of the radiance arriving along -ray.d at ray.o, with
  // at most max_order scattering events (medium and ground) contributing.
  double sample(const Ray& ray, std::mt19937_64& rng, int max_order = 1 << 30) const;
  // The mean of `paths` of them, seeded by `seed`.
  NaiveEstimate estimate(const Ray& ray, int paths, std::uint64_t seed, int max_order = 1 << 30) const;

  // First-order radiance by composite quadrature along the view ray (the sun
  // as a point; see above), steps of at most max_step_m.
  double single_scattering(const Ray& ray, double max_step_m = 50.0) const;

 private:
  struct Coefficients {
    double sigma_s = 0.0, sigma_t = 0.0;
  };
  double altitude(const glm::dvec3& p) const;
  Coefficients at(double altitude_m) const;
  double sigma_s_of(std::size_t constituent, double altitude_m) const;
  // The step length from p along d (see above).
  double step_length(const glm::dvec3& p, const glm::dvec3& d) const;
  // Where the ray leaves the atmosphere or meets the ground (t, and whether
  // the ground), or t < 0 when it never enters the atmosphere.
  double segment_end(const Ray& ray, bool* ground) const;
  // The phase function of the mixture at p for the cosine mu.
  double mixture_phase(double altitude_m, double mu) const;
  // The sun's light scattered at a vertex (NEE, one disk direction).
  double sun_at_medium_vertex(const glm::dvec3& p, const glm::dvec3& d_in, std::mt19937_64& rng) const;
  double sun_at_ground(const glm::dvec3& p, const glm::dvec3& n, std::mt19937_64& rng) const;
  glm::dvec3 sample_sun_direction(std::mt19937_64& rng) const;

  const Scene& scene_;
  double lambda_;
  double R_, top_;
  double sun_radiance_;      // radiance in the disk (or irradiance of a point sun)
  double sun_solid_angle_;   // of the disk (1 for a point sun: the delta's weight)
  double cos_alpha_;
  std::vector<PhaseFunction> phases_;                   // per constituent, at lambda
  std::vector<double> table_sigma_t_;                   // [altitude step]
  std::vector<std::vector<double>> table_sigma_s_;      // [constituent][altitude step]
};

}  // namespace skyfarm::testing
