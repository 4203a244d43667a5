// The atmosphere as the path tracer queries it, for the kWavelengthsPerPath
// wavelengths of a path: coefficients at a point, per-shell majorants, and the
// mixture phase function of the scattering constituents.
//
//   sigma_s(h, l) = sum_c sigma_s,c(h, l),  sigma_a likewise;
//   p(mu; h, l)   = sum_c sigma_s,c(h, l) p_c(mu; l) / sigma_s(h, l)   (mixture phase).
// Majorants come from a MajorantGrid over the render's wavelength range,
// inflated by 1e-9 relative so round-off at shell boundaries cannot make
// sigma_t exceed them.
#pragma once
#include <array>
#include <vector>

#include "common/atmosphere/atmosphere.h"
#include "common/atmosphere/majorant_grid.h"
#include "common/spectrum/sampled_spectrum.h"

namespace skyfarm {

inline constexpr int kMaxScatterers = 16;

// Coefficients at one point for the path's wavelengths.
struct MediumPoint {
  SampledSpectrum sigma_a, sigma_s;
  std::array<SampledSpectrum, kMaxScatterers> sigma_s_c;  // per scattering constituent
};

// The phase functions of the scattering constituents at the path's
// wavelengths (Earth's air: Rayleigh with Bucholtz's depolarisation at each
// wavelength; others: the same function at every wavelength).
class PathPhases {
 public:
  double eval(int scatterer, int wavelength, double mu) const;
  double sample_cos_theta(int scatterer, double u) const;  // at the hero wavelength
  int count() const { return count_; }

 private:
  friend class AtmosphereMedium;
  struct Entry {
    const PhaseFunction* shared = nullptr;  // wavelength-independent
    std::array<RayleighPhase, kWavelengthsPerPath> rayleigh{};  // used when shared == nullptr
  };
  std::array<Entry, kMaxScatterers> entries_{};
  int count_ = 0;
};

class AtmosphereMedium {
 public:
  AtmosphereMedium(const Atmosphere& atmosphere, double lambda_min_nm, double lambda_max_nm);

  const Atmosphere& atmosphere() const { return atmosphere_; }
  const MajorantGrid& majorants() const { return majorants_; }
  std::span<const double> shell_bottoms() const { return shell_bottoms_; }
  int scatterer_count() const { return static_cast<int>(scatterers_.size()); }
  // Name of scatterer s (the constituent's name).
  const std::string& scatterer_name(int s) const;

  // Majorant-grid bins of the path's wavelengths.
  std::array<std::size_t, kWavelengthsPerPath> bins(const SampledWavelengths& lambda) const;
  SampledSpectrum sigma_maj(std::size_t shell, const std::array<std::size_t, kWavelengthsPerPath>& bins) const;

  void point(double altitude_m, const SampledWavelengths& lambda, MediumPoint* out) const;
  PathPhases phases(const SampledWavelengths& lambda) const;

 private:
  const Atmosphere& atmosphere_;
  MajorantGrid majorants_;
  std::vector<double> shell_bottoms_;
  std::vector<int> scatterers_;  // constituent indices that scatter
  std::vector<int> absorbers_;   // constituent indices that absorb
};

}  // namespace skyfarm
