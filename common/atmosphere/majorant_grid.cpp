#include "common/atmosphere/majorant_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace skyfarm {

std::vector<double> majorant_shell_boundaries(double top, double step) {
  std::vector<double> b{0.0};
  while (b.back() < top) {
    const double h = b.back();
    const double dh = h < 2000.0 ? 200.0 : std::min(10000.0, 0.1 * h);
    double next = std::min(top, h + dh);
    // Snap to the altitude grid (at least one step up).
    if (step > 0.0 && next < top) next = std::min(top, std::max(h + step, std::round(next / step) * step));
    b.push_back(next);
  }
  return b;
}

MajorantGrid::MajorantGrid(const Atmosphere& atmosphere, double lambda_min_nm, double lambda_max_nm, double bin_nm,
                           double altitude_step_m)
    : shell_bottoms_(majorant_shell_boundaries(atmosphere.top_altitude_m(), altitude_step_m)),
      lambda_min_(lambda_min_nm),
      lambda_max_(lambda_max_nm) {
  if (!(lambda_max_nm > lambda_min_nm) || !(bin_nm > 0.0))
    throw std::invalid_argument("majorant grid: needs lambda_max > lambda_min and a positive bin width");
  bins_ = static_cast<std::size_t>(std::ceil((lambda_max_nm - lambda_min_nm) / bin_nm));
  bins_ = std::max<std::size_t>(bins_, 1);
  bin_width_ = (lambda_max_nm - lambda_min_nm) / static_cast<double>(bins_);
  table_.assign(shell_count() * bins_, 0.0);
  for (std::size_t i = 0; i < shell_count(); ++i) {
    const double h0 = shell_bottoms_[i], h1 = shell_bottoms_[i + 1];
    for (const auto& c : atmosphere.constituents()) {
      const double rho_max = c.density.max_on(h0, h1);
      if (rho_max == 0.0) continue;
      for (std::size_t j = 0; j < bins_; ++j) {
        const double l0 = lambda_min_ + bin_width_ * static_cast<double>(j);
        const double l1 = (j + 1 == bins_) ? lambda_max_ : l0 + bin_width_;
        const double k_max = c.k_scattering.max_on(l0, l1, h0, h1) + c.k_absorption.max_on(l0, l1, h0, h1);
        table_[i * bins_ + j] += rho_max * k_max;
      }
    }
  }
}

std::size_t MajorantGrid::shell_of(double altitude_m) const {
  const double h = std::max(altitude_m, 0.0);
  if (h > shell_bottoms_.back()) return shell_count();
  const auto it = std::upper_bound(shell_bottoms_.begin(), shell_bottoms_.end(), h);
  const std::size_t i = static_cast<std::size_t>(it - shell_bottoms_.begin());
  return std::min(i == 0 ? 0 : i - 1, shell_count() - 1);
}

std::size_t MajorantGrid::bin_of(double lambda_nm) const {
  const double x = (lambda_nm - lambda_min_) / bin_width_;
  if (!(x > 0.0)) return 0;
  return std::min(static_cast<std::size_t>(x), bins_ - 1);
}

}  // namespace skyfarm
