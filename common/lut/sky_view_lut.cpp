#include "common/lut/sky_view_lut.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "common/lut/bilinear.h"
#include "common/lut/invalid_argument.h"
#include "common/lut/multiple_scattering_bands.h"
#include "common/lut/scattering_march.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm {

SkyViewLut SkyViewLut::build(const MediumTable& medium, const TransmittanceLut& transmittance,
                             const MultipleScatteringLut& multiple_scattering, const GroundIrradianceLut& ground,
                             double observer_radius_m, double mu_s, std::span<const double> sun_irradiance,
                             int azimuth_columns, int zenith_rows, int steps, const MultipleScatteringBands* bands,
                             const BandViewGrid& band_grid) {
  if (azimuth_columns < 2 || zenith_rows < 4 || steps < 1 || band_grid.row_stride < 1 ||
      band_grid.column_stride < 1 || band_grid.steps < 1)
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
  if (bands && bands->max_band() > 0) s.add_bands(medium, transmittance, *bands, r, mu_s, sun_irradiance, band_grid);
  return s;
}

namespace {

// The coarse nodes of [first, last]: every stride-th index and the last.
std::vector<int> coarse_nodes(int first, int last, int stride) {
  std::vector<int> nodes;
  for (int i = first; i < last; i += stride) nodes.push_back(i);
  nodes.push_back(last);
  return nodes;
}

// Index n of the coarse interval holding i, and the weight of node n + 1.
std::pair<std::size_t, float> bracket(const std::vector<int>& nodes, int i) {
  if (nodes.size() == 1) return {0, 0.0f};
  std::size_t n = 0;
  while (n + 2 < nodes.size() && nodes[n + 1] <= i) ++n;
  return {n, static_cast<float>(i - nodes[n]) / static_cast<float>(nodes[n + 1] - nodes[n])};
}

}  // namespace

void SkyViewLut::add_bands(const MediumTable& medium, const TransmittanceLut& transmittance,
                           const MultipleScatteringBands& bands, double r, double mu_s,
                           std::span<const double> sun_irradiance, const BandViewGrid& grid) {
  const std::size_t B = static_cast<std::size_t>(bins_), cols = static_cast<std::size_t>(mapping_.n_azimuth);
  const double R = medium.planet_radius_m(), R_top = medium.top_radius_m();
  const double sin_s = std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s));
  const std::vector<int> col_nodes = coarse_nodes(0, mapping_.n_azimuth - 1, grid.column_stride);
  const std::vector<int> halves[2] = {coarse_nodes(0, mapping_.n_sky - 1, grid.row_stride),
                                      coarse_nodes(mapping_.n_sky, mapping_.rows() - 1, grid.row_stride)};
  ScatteringMarch march(medium, transmittance, nullptr, nullptr);
  std::vector<double> L(B);
  for (const std::vector<int>& row_nodes : halves) {
    // The bands' radiance at the half's coarse nodes [row node][column node][bin].
    std::vector<float> coarse(row_nodes.size() * col_nodes.size() * B, 0.0f);
    for (std::size_t i = 0; i < row_nodes.size(); ++i) {
      bool hits_ground;
      const double theta = mapping_.zenith_of_row(row_nodes[i], &hits_ground);
      const double mu = std::cos(theta), sin_theta = std::sin(theta);
      const double t_end = hits_ground ? lut::distance_to_ground(r, mu, R) : lut::distance_to_top(r, mu, R_top);
      if (!(t_end > 0.0)) continue;
      march.prepare(r, mu, t_end, hits_ground, grid.steps);
      for (std::size_t j = 0; j < col_nodes.size(); ++j) {
        const double nu = mu * mu_s + sin_theta * sin_s * mapping_.cos_phi_of_column(col_nodes[j]);
        std::fill(L.begin(), L.end(), 0.0);
        march.add_bands(bands, nu, mu_s, L.data());
        float* c = coarse.data() + (i * col_nodes.size() + j) * B;
        for (std::size_t b = 0; b < B; ++b) c[b] = static_cast<float>(L[b] * sun_irradiance[b]);
      }
    }
    for (int row = row_nodes.front(); row <= row_nodes.back(); ++row) {
      const auto [i, fi] = bracket(row_nodes, row);
      const std::size_t i1 = std::min(i + 1, row_nodes.size() - 1);
      for (std::size_t col = 0; col < cols; ++col) {
        const auto [j, fj] = bracket(col_nodes, static_cast<int>(col));
        const std::size_t j1 = std::min(j + 1, col_nodes.size() - 1);
        const std::size_t n = col_nodes.size();
        const float *c00 = coarse.data() + (i * n + j) * B, *c01 = coarse.data() + (i * n + j1) * B;
        const float *c10 = coarse.data() + (i1 * n + j) * B, *c11 = coarse.data() + (i1 * n + j1) * B;
        const float w00 = (1.0f - fi) * (1.0f - fj), w01 = (1.0f - fi) * fj, w10 = fi * (1.0f - fj), w11 = fi * fj;
        float* out = values_.data() + (static_cast<std::size_t>(row) * cols + col) * B;
        for (std::size_t b = 0; b < B; ++b)
          out[b] = std::max(0.0f, out[b] + w00 * c00[b] + w01 * c01[b] + w10 * c10[b] + w11 * c11[b]);
      }
    }
  }
}

void SkyViewLut::lookup(double mu, double cos_phi, double* out) const {
  const lut::ViewMapping::Position p = mapping_.locate(mu, cos_phi);
  const std::size_t B = static_cast<std::size_t>(bins_), cols = static_cast<std::size_t>(mapping_.n_azimuth);
  lut::BilinearF(values_.data() + (p.row * cols + p.column) * B, cols * B, B, p.f_row, p.f_column).eval(bins_, out);
}

}  // namespace skyfarm
