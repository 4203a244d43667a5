#include "common/lut/aerial_perspective_lut.h"

#include <algorithm>
#include <cmath>

#include "common/lut/invalid_argument.h"
#include "common/lut/scattering_march.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm {

AerialPerspectiveLut AerialPerspectiveLut::build(const MediumTable& medium, const TransmittanceLut& transmittance,
                                                 const MultipleScatteringLut& multiple_scattering,
                                                 double observer_radius_m, double mu_s,
                                                 std::span<const double> sun_irradiance, int azimuth_columns,
                                                 int zenith_rows, int slices, double max_distance_m) {
  if (azimuth_columns < 2 || zenith_rows < 4 || slices < 2 || !(max_distance_m > 0.0))
    throw lut::invalid_argument("aerial-perspective LUT: bad resolution ", azimuth_columns, "x", zenith_rows, "x",
                                slices, " up to ", max_distance_m, " m");
  AerialPerspectiveLut a;
  a.bins_ = medium.bins();
  a.slices_ = slices;
  a.d_max_ = max_distance_m;
  a.R_top_ = medium.top_radius_m();
  const double R = medium.planet_radius_m(), R_top = medium.top_radius_m();
  const double r = std::clamp(observer_radius_m, R, R_top);
  a.mapping_ = lut::ViewMapping(r, R, zenith_rows, azimuth_columns);
  const std::size_t B = static_cast<std::size_t>(a.bins_), cols = static_cast<std::size_t>(azimuth_columns);
  const std::size_t rows = static_cast<std::size_t>(a.mapping_.rows()), N = static_cast<std::size_t>(slices);
  a.L_.resize(N * rows * cols * B);  // every slice written below (slice 0: zeros)
  a.T_.resize(N * rows * B);
  a.end_.assign(rows, 0.0);
  const double sin_s = std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s));

  ScatteringMarch march(medium, transmittance, &multiple_scattering, nullptr);
  const std::size_t CB = static_cast<std::size_t>(medium.scatterers()) * B;
  std::vector<float> phase(cols * CB);  // single precision, as the march uses it
  std::vector<double> nu(cols), boundaries(N), L(cols * B);
  for (std::size_t row = 0; row < rows; ++row) {
    bool hits_ground;
    const double theta = a.mapping_.zenith_of_row(static_cast<int>(row), &hits_ground);
    const double mu = std::cos(theta), sin_theta = std::sin(theta);
    const double t_limit = hits_ground ? lut::distance_to_ground(r, mu, R) : lut::distance_to_top(r, mu, R_top);
    a.end_[row] = std::min(t_limit, a.d_max_);
    for (std::size_t k = 0; k < N; ++k)
      boundaries[k] = a.end_[row] * sqr(static_cast<double>(k) / static_cast<double>(N - 1));
    march.prepare_boundaries(r, mu, boundaries, false);
    for (std::size_t k = 0; k < N; ++k)
      std::copy(march.T_before(static_cast<int>(k)), march.T_before(static_cast<int>(k)) + B,
                a.T_.begin() + static_cast<std::ptrdiff_t>((row * N + k) * B));  // (to float)
    for (std::size_t col = 0; col < cols; ++col) {
      nu[col] = mu * mu_s + sin_theta * sin_s * a.mapping_.cos_phi_of_column(static_cast<int>(col));
      medium.phase(nu[col], phase.data() + col * CB);
    }
    std::fill(L.begin(), L.end(), 0.0);
    for (std::size_t col = 0; col < cols; ++col) {  // slice 0 (d = 0): no light in-scattered yet
      float* out = a.L_.data() + (row * cols + col) * N * B;
      std::fill(out, out + B, 0.0f);
    }
    for (std::size_t k = 1; k < N; ++k) {
      march.add_inscattering(static_cast<int>(cols), nu.data(), phase.data(), mu_s, static_cast<int>(k - 1),
                             static_cast<int>(k), L.data());
      for (std::size_t col = 0; col < cols; ++col) {
        float* out = a.L_.data() + ((row * cols + col) * N + k) * B;
        for (std::size_t b = 0; b < B; ++b) out[b] = static_cast<float>(L[col * B + b] * sun_irradiance[b]);
      }
    }
  }
  return a;
}

// Bilinear in (row, column); along the slices linear in sqrt(d / d_end),
// d_end that of the looked-up direction, held beyond it.
void AerialPerspectiveLut::lookup(double mu, double cos_phi, double distance_m, double* L_in, double* T) const {
  const lut::ViewMapping::Position p = mapping_.locate(mu, cos_phi);
  const std::size_t B = static_cast<std::size_t>(bins_), cols = static_cast<std::size_t>(mapping_.n_azimuth);
  const std::size_t N = static_cast<std::size_t>(slices_);
  const double r = mapping_.r, R = mapping_.R;
  const double end =
      std::min(d_max_, p.ground ? lut::distance_to_ground(r, mu, R) : lut::distance_to_top(r, mu, R_top_));
  const double x = end > 0.0 ? std::sqrt(std::clamp(distance_m / end, 0.0, 1.0)) * static_cast<double>(N - 1) : 0.0;
  const std::size_t k = std::min(static_cast<std::size_t>(x), N - 2);
  const double f = x - static_cast<double>(k);
  std::fill(L_in, L_in + B, 0.0);
  std::fill(T, T + B, 0.0);
  for (std::size_t i = 0; i < 2; ++i) {
    const std::size_t row = p.row + i;
    const double w_row = i == 0 ? 1.0 - p.f_row : p.f_row;
    const float* t = T_.data() + (row * N + k) * B;
    for (std::size_t b = 0; b < B; ++b) T[b] += w_row * ((1.0 - f) * t[b] + f * t[B + b]);
    for (std::size_t j = 0; j < 2; ++j) {
      const double w = w_row * (j == 0 ? 1.0 - p.f_column : p.f_column);
      const float* l = L_.data() + ((row * cols + p.column + j) * N + k) * B;
      for (std::size_t b = 0; b < B; ++b) L_in[b] += w * ((1.0 - f) * l[b] + f * l[B + b]);
    }
  }
}

}  // namespace skyfarm
