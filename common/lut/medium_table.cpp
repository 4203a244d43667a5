#include "common/lut/medium_table.h"

#include <algorithm>
#include <cmath>

#include "common/lut/invalid_argument.h"

namespace skyfarm {

MediumTable MediumTable::build(const Atmosphere& atmosphere, const SpectralGrid& grid, int altitude_samples,
                               int phase_samples) {
  if (altitude_samples < 2 || phase_samples < 2)
    throw lut::invalid_argument("medium table: need >= 2 altitude and phase samples, got ", altitude_samples, " and ",
                                phase_samples);
  MediumTable m;
  m.bins_ = grid.size();
  m.altitude_samples_ = altitude_samples;
  m.phase_samples_ = phase_samples;
  m.R_ = atmosphere.planet_radius_m();
  m.R_top_ = atmosphere.top_radius_m();
  m.dh_ = atmosphere.top_altitude_m() / (altitude_samples - 1);
  m.inv_dh_ = 1.0 / m.dh_;

  std::vector<const Constituent*> scatterers;
  for (const Constituent& c : atmosphere.constituents())
    if (c.scatters()) scatterers.push_back(&c);
  m.scatterers_ = static_cast<int>(scatterers.size());

  const std::size_t B = static_cast<std::size_t>(m.bins_), C = scatterers.size();
  const std::size_t H = static_cast<std::size_t>(altitude_samples);
  m.sigma_t_.assign(H * B, 0.0);
  m.sigma_s_.assign(H * B, 0.0);
  m.sigma_s_c_.assign(H * C * B, 0.0);
  for (std::size_t i = 0; i < H; ++i) {
    // The last node sits exactly on the top (the coefficients' own cut-off
    // is "above the top", so the top itself still has its values).
    const double h = std::min(static_cast<double>(i) * m.dh_, atmosphere.top_altitude_m());
    for (std::size_t b = 0; b < B; ++b) {
      const double lambda = grid.centre_nm(static_cast<int>(b));
      double s_t = 0.0, s_s = 0.0;
      for (const Constituent& c : atmosphere.constituents()) {
        const double s = c.sigma_s(h, lambda), a = c.sigma_a(h, lambda);
        s_t += s + a;
        s_s += s;
      }
      m.sigma_t_[i * B + b] = s_t;
      m.sigma_s_[i * B + b] = s_s;
      for (std::size_t c = 0; c < C; ++c) m.sigma_s_c_[(i * C + c) * B + b] = scatterers[c]->sigma_s(h, lambda);
    }
  }

  m.phase_functions_.reserve(C * B);
  for (std::size_t c = 0; c < C; ++c)
    for (std::size_t b = 0; b < B; ++b)
      m.phase_functions_.push_back(scatterers[c]->phase_at(grid.centre_nm(static_cast<int>(b))));
  const std::size_t P = static_cast<std::size_t>(phase_samples);
  m.phase_table_.assign(P * C * B, 0.0);
  for (std::size_t k = 0; k < P; ++k) {
    const double x = static_cast<double>(k) / static_cast<double>(P - 1);  // sin(theta/2)
    const double nu = 1.0 - 2.0 * x * x;
    for (std::size_t j = 0; j < C * B; ++j) m.phase_table_[k * C * B + j] = m.phase_functions_[j].eval(nu);
  }

  m.albedo_.resize(B);
  for (std::size_t b = 0; b < B; ++b) m.albedo_[b] = atmosphere.ground().albedo(grid.centre_nm(static_cast<int>(b)));
  return m;
}

MediumTable::Node MediumTable::locate(double altitude_m) const {
  const double u = std::clamp(altitude_m * inv_dh_, 0.0, static_cast<double>(altitude_samples_ - 1));
  const std::size_t i = std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(altitude_samples_ - 2));
  return {i, u - static_cast<double>(i)};
}

// Linear in x = sin(theta/2) = sqrt((1 - nu)/2) between the table's nodes.
void MediumTable::phase(double nu, double* out) const {
  const double x = std::sqrt(std::clamp(0.5 * (1.0 - nu), 0.0, 1.0));
  const double u = x * (phase_samples_ - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(phase_samples_ - 2));
  interpolate(phase_table_, Node{i, u - static_cast<double>(i)}, scatterers_ * bins_, out);
}

void MediumTable::phase_exact(double nu, double* out) const {
  for (std::size_t j = 0; j < phase_functions_.size(); ++j) out[j] = phase_functions_[j].eval(nu);
}

std::size_t MediumTable::memory_bytes() const {
  return sizeof(double) *
             (sigma_t_.size() + sigma_s_.size() + sigma_s_c_.size() + phase_table_.size() + albedo_.size()) +
         sizeof(PhaseFunction) * phase_functions_.size();
}

}  // namespace skyfarm
