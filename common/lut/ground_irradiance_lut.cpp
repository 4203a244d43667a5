#include "common/lut/ground_irradiance_lut.h"

#include <algorithm>
#include <cmath>

#include "common/core/constants.h"
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
  constexpr std::size_t kAzimuths = 4;
  const int rings = std::max(1, directions / static_cast<int>(kAzimuths));
  const std::size_t M = static_cast<std::size_t>(mu_s_samples), V = kAzimuths * M;  // views per ring
  const std::size_t CB = static_cast<std::size_t>(medium.scatterers()) * B;
  std::vector<double> mu_s(M), sin_s(M), cos_phi(kAzimuths), w_phi(kAzimuths);
  std::vector<double> nu(V), mu_s_view(V), L(V * B);
  std::vector<float> phase(V * CB);  // single precision, as the march uses it
  for (std::size_t k = 0; k < M; ++k) {
    mu_s[k] = -1.0 + 2.0 * static_cast<double>(k) / static_cast<double>(M - 1);
    sin_s[k] = std::sqrt(std::max(0.0, 1.0 - mu_s[k] * mu_s[k]));
  }
  for (std::size_t j = 0; j < kAzimuths; ++j) {  // phi = pi t^2, both mirror images
    const double t = (static_cast<double>(j) + 0.5) / kAzimuths;
    cos_phi[j] = std::cos(kPi * t * t);
    w_phi[j] = 2.0 * kPi * 2.0 * t / kAzimuths;
  }
  for (int i = 0; i < rings; ++i) {
    // From the ground, upwards: the ray never meets the ground again.  Every
    // (azimuth, sun) is a view of the ring's march.
    const double mu = (i + 0.5) / rings, w_mu = mu / rings, sin_theta = std::sqrt((1.0 - mu) * (1.0 + mu));
    march.prepare(R, mu, lut::distance_to_top(R, mu, R_top), false, steps);
    for (std::size_t j = 0; j < kAzimuths; ++j)
      for (std::size_t k = 0; k < M; ++k) {
        const std::size_t v = j * M + k;
        nu[v] = sin_theta * cos_phi[j] * sin_s[k] + mu * mu_s[k];  // w = (sin cos phi, ., mu), s = (sin_s, 0, mu_s)
        mu_s_view[v] = mu_s[k];
        medium.phase(nu[v], phase.data() + v * CB);
      }
    std::fill(L.begin(), L.end(), 0.0);
    march.add_inscattering(static_cast<int>(V), nu.data(), mu_s_view.data(), phase.data(), 0, march.steps(), L.data());
    for (std::size_t j = 0; j < kAzimuths; ++j)
      for (std::size_t k = 0; k < M; ++k)
        for (std::size_t b = 0; b < B; ++b) g.values_[k * B + b] += w_mu * w_phi[j] * L[(j * M + k) * B + b];
  }
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
