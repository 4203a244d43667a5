#include "common/lut/sky_view_lut.h"

#include <algorithm>
#include <cmath>

#include "common/lut/bilinear.h"
#include "common/lut/invalid_argument.h"
#include "common/lut/scattering_march.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm {

SkyViewLut SkyViewLut::build(const MediumTable& medium, const TransmittanceLut& transmittance,
                             const MultipleScatteringLut& multiple_scattering, const GroundIrradianceLut& ground,
                             double observer_radius_m, double mu_s, std::span<const double> sun_irradiance,
                             int azimuth_columns, int zenith_rows, int steps) {
  if (azimuth_columns < 2 || zenith_rows < 4 || steps < 1)
    throw lut::invalid_argument("sky-view LUT: bad resolution ", azimuth_columns, "x", zenith_rows, ", ", steps,
                                " steps");
  SkyViewLut s;
  s.bins_ = medium.bins();
  const double R = medium.planet_radius_m(), R_top = medium.top_radius_m();
  const double r = std::clamp(observer_radius_m, R, R_top);
  s.mapping_ = lut::ViewMapping(r, R, zenith_rows, azimuth_columns);
  const std::size_t B = static_cast<std::size_t>(s.bins_), cols = static_cast<std::size_t>(azimuth_columns);
  s.values_.resize(static_cast<std::size_t>(s.mapping_.rows()) * cols * B);  // every row written below
  const double sin_s = std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s));

  ScatteringMarch march(medium, transmittance, &multiple_scattering, &ground);
  const std::size_t CB = static_cast<std::size_t>(medium.scatterers()) * B;
  std::vector<float> phase(cols * CB);  // single precision, as the march uses it
  std::vector<double> nu(cols), L(cols * B);
  for (int row = 0; row < s.mapping_.rows(); ++row) {
    bool hits_ground;
    const double theta = s.mapping_.zenith_of_row(row, &hits_ground);
    const double mu = std::cos(theta), sin_theta = std::sin(theta);
    const double t_end = hits_ground ? lut::distance_to_ground(r, mu, R) : lut::distance_to_top(r, mu, R_top);
    march.prepare(r, mu, t_end, hits_ground, steps);
    float* out = s.values_.data() + static_cast<std::size_t>(row) * cols * B;
    if (hits_ground && t_end == 0.0) {
      // Looking down from the ground itself (an observer at 0 m): no air in
      // between, and the ground at the observer's feet, whatever the azimuth
      // (add_ground's nu enters only as t_end nu): one value for the row.
      std::fill(L.begin(), L.begin() + static_cast<std::ptrdiff_t>(B), 0.0);
      march.add_ground(0.0, mu_s, L.data());
      for (std::size_t col = 0; col < cols; ++col)
        for (std::size_t b = 0; b < B; ++b) out[col * B + b] = static_cast<float>(L[b] * sun_irradiance[b]);
      continue;
    }
    for (std::size_t col = 0; col < cols; ++col) {
      // nu = v . s for v = (sin_theta cos_phi, sin_theta sin_phi, mu), s = (sin_s, 0, mu_s).
      nu[col] = mu * mu_s + sin_theta * sin_s * s.mapping_.cos_phi_of_column(static_cast<int>(col));
      medium.phase(nu[col], phase.data() + col * CB);
    }
    std::fill(L.begin(), L.end(), 0.0);
    march.add_inscattering(static_cast<int>(cols), nu.data(), phase.data(), mu_s, 0, march.steps(), L.data());
    for (std::size_t col = 0; col < cols; ++col) {
      double* Lc = L.data() + col * B;
      march.add_ground(nu[col], mu_s, Lc);
      for (std::size_t b = 0; b < B; ++b) out[col * B + b] = static_cast<float>(Lc[b] * sun_irradiance[b]);
    }
  }
  return s;
}

void SkyViewLut::lookup(double mu, double cos_phi, double* out) const {
  const lut::ViewMapping::Position p = mapping_.locate(mu, cos_phi);
  const std::size_t B = static_cast<std::size_t>(bins_), cols = static_cast<std::size_t>(mapping_.n_azimuth);
  lut::BilinearF(values_.data() + (p.row * cols + p.column) * B, cols * B, B, p.f_row, p.f_column).eval(bins_, out);
}

}  // namespace skyfarm
