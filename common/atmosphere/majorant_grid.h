// Majorants of extinction for unbiased free-flight sampling (delta / ratio /
// spectral tracking): for each altitude shell [h_i, h_{i+1}] and each
// wavelength bin [l_j, l_{j+1}] a bound
//     sigma_maj(i, j) >= sigma_t(h, lambda)  for all h in the shell, lambda in the bin,
// built from exact per-constituent bounds: max of rho over the shell (exact for
// every density kind) times max of k over the bin and the shell's temperatures.
// A product of maxima bounds the max of products, so the bound holds; it is
// tight to within the variation of rho across a shell and k across a bin.
//
// Shells: 200 m thick up to 2 km, then 10 % of their base altitude (at most
// 10 km) up to the top (51 shells for a 100 km atmosphere: every ray pays for
// each shell it crosses, every loose bound for extra null collisions);
// wavelength bins of 1 nm (fewer for a short range).
// Above the top sigma_maj = 0.
#pragma once
#include <vector>

#include "common/atmosphere/atmosphere.h"

namespace skyfarm {

class MajorantGrid {
 public:
  // altitude_step_m > 0 puts every shell boundary on a multiple of it (and the
  // top), so that coefficients tabulated on that altitude grid and
  // interpolated linearly stay under the shell's bound (render/atmosphere_medium.h).
  MajorantGrid(const Atmosphere& atmosphere, double lambda_min_nm, double lambda_max_nm, double bin_nm = 1.0,
               double altitude_step_m = 0.0);

  std::size_t shell_count() const { return shell_bottoms_.size() - 1; }
  std::size_t bin_count() const { return bins_; }
  // Shell boundaries: shell i spans [shell_bottom(i), shell_bottom(i + 1)].
  double shell_bottom(std::size_t i) const { return shell_bottoms_[i]; }
  // Shell containing altitude h (h < 0 reads as 0); shell_count() above the top.
  std::size_t shell_of(double altitude_m) const;
  std::size_t bin_of(double lambda_nm) const;

  double sigma_maj(std::size_t shell, std::size_t bin) const {
    return shell >= shell_count() ? 0.0 : table_[shell * bins_ + bin];
  }
  double sigma_maj_at(double altitude_m, double lambda_nm) const {
    return sigma_maj(shell_of(altitude_m), bin_of(lambda_nm));
  }

  double bin_width_nm() const { return bin_width_; }
  double lambda_min_nm() const { return lambda_min_; }
  double lambda_max_nm() const { return lambda_max_; }

 private:
  std::vector<double> shell_bottoms_;
  double lambda_min_, lambda_max_, bin_width_;
  std::size_t bins_;
  std::vector<double> table_;  // shell-major
};

// The shell boundaries used by MajorantGrid for an atmosphere of this top.
std::vector<double> majorant_shell_boundaries(double top_altitude_m, double altitude_step_m = 0.0);

}  // namespace skyfarm
