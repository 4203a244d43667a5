#include "common/render/atmosphere_medium.h"

#include <stdexcept>

#include "common/atmosphere/rayleigh.h"

namespace skyfarm {

double PathPhases::eval(int s, int i, double mu) const {
  const Entry& e = entries_[static_cast<std::size_t>(s)];
  return e.shared ? e.shared->eval(mu) : e.rayleigh[static_cast<std::size_t>(i)].eval(mu);
}

double PathPhases::sample_cos_theta(int s, double u) const {
  const Entry& e = entries_[static_cast<std::size_t>(s)];
  return e.shared ? e.shared->sample_cos_theta(u) : e.rayleigh[0].sample_cos_theta(u);
}

AtmosphereMedium::AtmosphereMedium(const Atmosphere& atmosphere, double lambda_min_nm, double lambda_max_nm)
    : atmosphere_(atmosphere), majorants_(atmosphere, lambda_min_nm, lambda_max_nm) {
  for (std::size_t i = 0; i <= majorants_.shell_count(); ++i) shell_bottoms_.push_back(majorants_.shell_bottom(i));
  const auto& cs = atmosphere_.constituents();
  for (std::size_t c = 0; c < cs.size(); ++c) {
    if (cs[c].scatters()) scatterers_.push_back(static_cast<int>(c));
    if (cs[c].absorbs()) absorbers_.push_back(static_cast<int>(c));
  }
  if (scatterers_.size() > static_cast<std::size_t>(kMaxScatterers))
    throw std::invalid_argument("atmosphere: at most 16 scattering constituents");
}

const std::string& AtmosphereMedium::scatterer_name(int s) const {
  return atmosphere_.constituents()[static_cast<std::size_t>(scatterers_[static_cast<std::size_t>(s)])].name;
}

std::array<std::size_t, kWavelengthsPerPath> AtmosphereMedium::bins(const SampledWavelengths& lambda) const {
  std::array<std::size_t, kWavelengthsPerPath> b{};
  for (int i = 0; i < kWavelengthsPerPath; ++i) b[i] = majorants_.bin_of(lambda.lambda_nm[i]);
  return b;
}

SampledSpectrum AtmosphereMedium::sigma_maj(std::size_t shell,
                                            const std::array<std::size_t, kWavelengthsPerPath>& bins) const {
  SampledSpectrum m;
  for (int i = 0; i < kWavelengthsPerPath; ++i) m[i] = majorants_.sigma_maj(shell, bins[i]) * (1.0 + 1e-9);
  return m;
}

void AtmosphereMedium::point(double h, const SampledWavelengths& lambda, MediumPoint* out) const {
  out->sigma_a = SampledSpectrum(0.0);
  out->sigma_s = SampledSpectrum(0.0);
  if (h > atmosphere_.top_altitude_m()) {
    for (std::size_t s = 0; s < scatterers_.size(); ++s) out->sigma_s_c[s] = SampledSpectrum(0.0);
    return;
  }
  const auto& cs = atmosphere_.constituents();
  for (std::size_t s = 0; s < scatterers_.size(); ++s) {
    const Constituent& c = cs[static_cast<std::size_t>(scatterers_[s])];
    const double rho = c.density.eval(h);
    SampledSpectrum& sc = out->sigma_s_c[s];
    for (int i = 0; i < kWavelengthsPerPath; ++i) sc[i] = rho * c.k_scattering.eval(lambda.lambda_nm[i], h);
    out->sigma_s += sc;
  }
  for (int a : absorbers_) {
    const Constituent& c = cs[static_cast<std::size_t>(a)];
    const double rho = c.density.eval(h);
    for (int i = 0; i < kWavelengthsPerPath; ++i) out->sigma_a[i] += rho * c.k_absorption.eval(lambda.lambda_nm[i], h);
  }
}

PathPhases AtmosphereMedium::phases(const SampledWavelengths& lambda) const {
  PathPhases p;
  p.count_ = static_cast<int>(scatterers_.size());
  const auto& cs = atmosphere_.constituents();
  for (std::size_t s = 0; s < scatterers_.size(); ++s) {
    const Constituent& c = cs[static_cast<std::size_t>(scatterers_[s])];
    auto& e = p.entries_[s];
    if (c.rayleigh_depolarization_from_bucholtz) {
      e.shared = nullptr;
      for (int i = 0; i < kWavelengthsPerPath; ++i) {
        const double rho_n = rayleigh::depolarization(lambda.lambda_nm[i]);
        e.rayleigh[static_cast<std::size_t>(i)] = RayleighPhase{rho_n, rho_n / (2.0 - rho_n)};
      }
    } else {
      e.shared = &c.phase;
    }
  }
  return p;
}

}  // namespace skyfarm
