#include "common/lut/ground_irradiance_lut.h"

#include <algorithm>
#include <cmath>

#include "common/core/constants.h"
#include "common/lut/fibonacci_directions.h"
#include "common/lut/invalid_argument.h"
#include "common/lut/scattering_march.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm {

GroundIrradianceLut GroundIrradianceLut::build(const MediumTable& medium, const TransmittanceLut& transmittance,
                                               const MultipleScatteringLut& multiple_scattering, int mu_s_samples,
                                               int directions, int steps) {
  if (mu_s_samples < 2 || directions < 1 || steps < 1)
    throw lut::invalid_argument("ground irradiance LUT: bad resolution ", mu_s_samples, ", ", directions,
                                " directions, ", steps, " steps");
  GroundIrradianceLut g;
  g.bins_ = medium.bins();
  g.n_mu_s_ = mu_s_samples;
  const std::size_t B = static_cast<std::size_t>(g.bins_);
  g.values_.assign(static_cast<std::size_t>(mu_s_samples) * B, 0.0);
  const double R = medium.planet_radius_m(), R_top = medium.top_radius_m();
  ScatteringMarch march(medium, transmittance, &multiple_scattering, nullptr);
  const std::size_t M = static_cast<std::size_t>(mu_s_samples), CB = static_cast<std::size_t>(medium.scatterers()) * B;
  std::vector<double> mu_s(M), nu(M), phase(M * CB);
  for (std::size_t k = 0; k < M; ++k) mu_s[k] = -1.0 + 2.0 * static_cast<double>(k) / static_cast<double>(M - 1);
  for (const glm::dvec3& w : lut::fibonacci_cosine_hemisphere(directions)) {
    // From the ground, upwards: the ray never meets the ground again.  Every
    // sun (node) is a view of the same march.
    march.prepare(R, w.z, lut::distance_to_top(R, w.z, R_top), false, steps);
    for (std::size_t k = 0; k < M; ++k) {
      nu[k] = w.x * std::sqrt(std::max(0.0, 1.0 - mu_s[k] * mu_s[k])) + w.z * mu_s[k];  // s = (sin, 0, mu_s)
      medium.phase(nu[k], phase.data() + k * CB);
    }
    march.add_inscattering(mu_s_samples, nu.data(), mu_s.data(), phase.data(), 0, march.steps(), g.values_.data());
  }
  for (double& v : g.values_) v *= kPi / directions;
  return g;
}

void GroundIrradianceLut::lookup_add(double mu_s, double* out) const {
  const double u = std::clamp(0.5 * (mu_s + 1.0), 0.0, 1.0) * (n_mu_s_ - 1);
  const std::size_t k = std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(n_mu_s_ - 2));
  const double f = u - static_cast<double>(k);
  const double* v0 = values_.data() + k * static_cast<std::size_t>(bins_);
  const double* v1 = v0 + bins_;
  for (int b = 0; b < bins_; ++b) out[b] += v0[b] + f * (v1[b] - v0[b]);
}

}  // namespace skyfarm
