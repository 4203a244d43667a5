// The atmosphere as the path tracer queries it, for the kWavelengthsPerPath
// wavelengths of a path: coefficients at a point, per-shell majorants, and the
// mixture phase function of the scattering constituents.
//
//   sigma_s(h, l) = sum_c rho_c(h) k_s,c(l),  sigma_a likewise (ozone: k_a(l, T(h)));
//   p(mu; h, l)   = sum_c sigma_s,c(h, l) p_c(mu; l) / sigma_s(h, l)   (mixture phase).
//
// For speed every density rho_c is tabulated on a uniform altitude grid
// (<= 25 m steps), every coefficient k on a uniform wavelength grid (1/16 of
// a majorant bin), both from the exact model and interpolated linearly: O(1)
// lookups instead of the model's searches and powers; the per-path wavelength
// factors are looked up once per path (PathCoefficients).  The tabulated
// model differs from the exact one by < 1e-5 relative for smooth profiles
// and coincides with it at every table knot (US76 layers, AFGL, Elterman).
// The majorant shells and bins are aligned with both grids, so the exact
// per-shell maxima still bound the interpolated values.  Majorants are then
// inflated by 1e-9 relative against round-off at shell boundaries.
#pragma once
#include <array>
#include <span>
#include <vector>

#include "common/atmosphere/atmosphere.h"
#include "common/atmosphere/majorant_grid.h"
#include "common/render/uniform_table_set.h"
#include "common/spectrum/sampled_spectrum.h"
#include "common/sun/sun.h"

namespace skyfarm {

inline constexpr int kMaxConstituents = 16;
inline constexpr int kMaxScatterers = kMaxConstituents;

// Coefficients at one point for the path's wavelengths.
struct MediumPoint {
  SampledSpectrum sigma_a, sigma_s;
  // Per scattering constituent, [scatterer][wavelength].  Plain arrays, left
  // uninitialised: point() writes every scatterer's entry and nothing reads
  // past them (a SampledSpectrum would zero all 16 on every MediumPoint made,
  // a few per path and one per shadow ray).
  std::array<std::array<double, kWavelengthsPerPath>, kMaxScatterers> sigma_s_c;
};

// The wavelength factors of every constituent at the path's wavelengths,
// and the other per-wavelength constants of a path.
struct PathCoefficients {
  // Up to 6 wavelength tables per constituent: k_s, and k_a or ozone's 5
  // temperature columns.
  static constexpr std::size_t kMaxColumns = 6 * kMaxConstituents;

  std::array<std::size_t, kWavelengthsPerPath> bins{};  // majorant bins
  SampledSpectrum sun_radiance;   // inside the disk (the irradiance for a point sun)
  SampledSpectrum ground_albedo;
  // The medium's wavelength tables at the path's wavelengths, by the
  // medium's column numbers (AtmosphereMedium::Columns).  Plain arrays, left
  // uninitialised past the medium's columns: only those are written and read.
  std::array<std::array<double, kWavelengthsPerPath>, kMaxColumns> k;
  SampledSpectrum k_of(std::size_t column) const {
    SampledSpectrum s;
    s.v = k[column];
    return s;
  }
};

// One set of majorant shells: boundaries (altitudes, K + 1 values) and
// sigma_maj per (shell, wavelength bin), inflated by 1e-9 relative.
//
// Stored bin-major (each bin's shells side by side): a path reads its own
// kWavelengthsPerPath bins shell after shell as it walks, so its values lie
// in a few cache lines per bin (the Earth's 51 fine shells: 408 bytes)
// instead of one cache line per (shell, wavelength) in a ~190 kB table.
struct ShellMajorants {
  std::vector<double> bottoms;
  std::vector<double> table;  // bin-major: table[bin * shell_count() + shell]
  std::size_t bins = 1;
  std::size_t shell_count() const { return bottoms.size() - 1; }
  // The bin's values, shell by shell.
  const double* bin_column(std::size_t bin) const { return table.data() + bin * shell_count(); }
  double& at(std::size_t shell, std::size_t bin) { return table[bin * shell_count() + shell]; }
  double at(std::size_t shell, std::size_t bin) const { return table[bin * shell_count() + shell]; }
  SampledSpectrum sigma_maj(std::size_t shell, const std::array<std::size_t, kWavelengthsPerPath>& b) const {
    SampledSpectrum m;
    for (int i = 0; i < kWavelengthsPerPath; ++i) m[i] = at(shell, b[static_cast<std::size_t>(i)]);
    return m;
  }
};

// The phase functions of the scattering constituents at the path's
// wavelengths (Earth's air: Rayleigh with Bucholtz's depolarisation at each
// wavelength; others: the same function at every wavelength).
class PathPhases {
 public:
  double eval(int scatterer, int wavelength, double mu) const {
    const auto s = static_cast<std::size_t>(scatterer);
    return shared_[s] ? shared_[s]->eval(mu) : rayleigh(s, static_cast<std::size_t>(wavelength)).eval(mu);
  }
  // Every wavelength's value at once: a wavelength-independent function is
  // evaluated once (the same value eval() gives at each wavelength).
  SampledSpectrum eval(int scatterer, double mu) const {
    const auto s = static_cast<std::size_t>(scatterer);
    if (shared_[s]) return SampledSpectrum(shared_[s]->eval(mu));
    SampledSpectrum p;
    for (std::size_t i = 0; i < kWavelengthsPerPath; ++i) p.v[i] = rayleigh(s, i).eval(mu);
    return p;
  }
  double sample_cos_theta(int scatterer, double u) const;  // at the hero wavelength
  int count() const { return count_; }

 private:
  friend class AtmosphereMedium;
  RayleighPhase rayleigh(std::size_t s, std::size_t i) const { return {depolarization_[s][i], gamma_[s][i]}; }
  // Per scatterer; plain arrays left uninitialised past count_ (one
  // PathPhases is made per path, and only the scatterers' entries are read).
  std::array<const PhaseFunction*, kMaxScatterers> shared_;  // wavelength-independent, or nullptr: Rayleigh
  std::array<std::array<double, kWavelengthsPerPath>, kMaxScatterers> depolarization_, gamma_;  // with nullptr
  int count_ = 0;
};

class AtmosphereMedium {
 public:
  AtmosphereMedium(const Atmosphere& atmosphere, double lambda_min_nm, double lambda_max_nm);

  const Atmosphere& atmosphere() const { return atmosphere_; }
  const MajorantGrid& majorants() const { return majorants_; }
  // Fine shells (tight bounds) for delta tracking of path segments; coarse
  // shells (a few, each the max of the fine ones it holds) for transmittance:
  // ratio tracking gains nothing from tight bounds, and every shell crossed
  // costs a ray/sphere root.
  const ShellMajorants& fine_shells() const { return fine_; }
  const ShellMajorants& coarse_shells() const { return coarse_; }
  // Residual ratio tracking of transmittance (residual_ratio_tracking.h):
  // on the fine shells, a control extinction sigma_c per (shell, bin), a
  // lower bound of sigma_t there (each constituent's smallest density in the
  // shell times its smallest coefficient in the bin, ozone's over every
  // temperature column), and the residual majorant sigma_maj - sigma_c.
  const ShellMajorants& control_shells() const { return control_; }
  const ShellMajorants& residual_shells() const { return residual_; }
  int scatterer_count() const { return static_cast<int>(scatterers_.size()); }
  const std::string& scatterer_name(int s) const;
  double altitude_step_m() const { return altitude_step_; }

  // Majorant-grid bins of the path's wavelengths.
  std::array<std::size_t, kWavelengthsPerPath> bins(const SampledWavelengths& lambda) const;
  // The per-path constants; `sun` gives the disk radiance.
  PathCoefficients path_coefficients(const SampledWavelengths& lambda, const Sun* sun = nullptr) const;
  void point(double altitude_m, const PathCoefficients& path, MediumPoint* out) const;
  PathPhases phases(const SampledWavelengths& lambda) const;

 private:
  void build_shells();
  void build_control_shells();

  // A constituent's columns in the set of altitude tables (its density) and
  // in the set of wavelength tables (k_s, then k_a or ozone's 5 columns).
  struct Columns {
    std::size_t rho = 0;
    std::size_t k_s = 0, k_a = 0;  // ozone: k_a is its first temperature column
    bool ozone = false;
  };

  const Atmosphere& atmosphere_;
  double altitude_step_;
  MajorantGrid majorants_;
  ShellMajorants fine_, coarse_, control_, residual_;
  // Every constituent's density, then (with ozone) US76 T(h), on the
  // uniform altitude grid (<= 25 m steps); every wavelength factor on the
  // uniform wavelength grid (1/16 of a majorant bin).  One set each: a
  // collision locates its altitude once, a path each wavelength once.
  UniformTableSet altitude_tables_, wavelength_tables_;
  std::vector<Columns> columns_;  // per constituent
  std::size_t temperature_column_ = 0;
  std::vector<int> scatterers_;  // constituent indices that scatter
  std::vector<int> absorbers_;   // constituent indices that absorb
};

}  // namespace skyfarm
