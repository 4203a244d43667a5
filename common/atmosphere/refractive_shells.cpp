#include "common/atmosphere/refractive_shells.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "common/atmosphere/air_refractive_index.h"

namespace skyfarm {

RefractivityProfile us76_refractivity_profile(double lambda_nm, double planet_radius_m, double top_altitude_m) {
  return {[lambda_nm](double h) { return air::us76_refractivity(lambda_nm, h); }, planet_radius_m, top_altitude_m};
}

RefractiveShells::RefractiveShells(std::vector<double> radii_m, std::vector<double> refractive_index)
    : radii_(std::move(radii_m)), index_(std::move(refractive_index)) {
  if (radii_.size() < 2 || radii_.size() != index_.size())
    throw std::invalid_argument("RefractiveShells: need one index per boundary radius, two at least");
  for (std::size_t i = 1; i < radii_.size(); ++i) {
    if (!(radii_[i] > radii_[i - 1])) throw std::invalid_argument("RefractiveShells: radii must increase");
    // alpha = -ln(n_{i+1} / n_i) / ln(r_{i+1} / r_i), both logarithms as log1p of
    // small relative steps to keep their digits.
    const double log_n = std::log1p((index_[i] - index_[i - 1]) / index_[i - 1]);
    const double log_r = std::log1p((radii_[i] - radii_[i - 1]) / radii_[i - 1]);
    beta_.push_back(1.0 + log_n / log_r);
  }
}

double RefractiveShells::index_at(int shell, double radius_m) const {
  const double alpha = 1.0 - beta_[shell];
  return index_[shell] * std::exp(-alpha * std::log1p((radius_m - radii_[shell]) / radii_[shell]));
}

// Shells grow from the ground up; each is halved from max_thickness_m until
// (n - 1) changes by at most max_refractivity_step across it (or it is 1 cm).
// The nodes sample the profile; the top node is vacuum.
RefractiveShells RefractiveShells::from_profile(const RefractivityProfile& profile, double max_refractivity_step,
                                                double max_thickness_m) {
  std::vector<double> radii{profile.planet_radius_m};
  std::vector<double> index{1.0 + profile.refractivity(0.0)};
  const double top = profile.top_altitude_m;
  double h = 0.0;
  double f0 = profile.refractivity(h);
  while (h < top) {
    double dh = std::min(max_thickness_m, top - h);
    double f1 = profile.refractivity(h + dh);
    while (dh > 0.01 && std::abs(f1 - f0) > max_refractivity_step) {
      dh *= 0.5;
      f1 = profile.refractivity(h + dh);
    }
    h = (top - (h + dh) < 1e-6) ? top : h + dh;
    radii.push_back(profile.planet_radius_m + h);
    index.push_back(h >= top ? 1.0 : 1.0 + f1);
    f0 = f1;
  }
  return RefractiveShells(std::move(radii), std::move(index));
}

int RefractiveShells::shell_at(double radius_m) const {
  const auto it = std::upper_bound(radii_.begin(), radii_.end(), radius_m);
  const int i = static_cast<int>(it - radii_.begin()) - 1;
  return std::clamp(i, 0, shell_count() - 1);
}

}  // namespace skyfarm
