#include "common/atmosphere/refraction_table.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/atmosphere/refracted_ray.h"
#include "common/atmosphere/refractive_shells.h"
#include "common/core/constants.h"

namespace skyfarm {
namespace {

// Catmull-Rom through the four nodes around t in [j, j + 1] (uniform spacing),
// with the end intervals using a one-sided (reflected) neighbour.
double catmull_rom(const std::vector<double>& y, double x) {
  const int n = static_cast<int>(y.size());
  const int j = std::clamp(static_cast<int>(std::floor(x)), 0, n - 2);
  const double t = x - j;
  const double p0 = j > 0 ? y[j - 1] : 2.0 * y[0] - y[1];
  const double p1 = y[j], p2 = y[j + 1];
  const double p3 = j + 2 < n ? y[j + 2] : 2.0 * y[n - 1] - y[n - 2];
  return p1 + 0.5 * t * ((p2 - p0) + t * ((2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) + t * (3.0 * (p1 - p2) + p3 - p0)));
}

}  // namespace

std::vector<double> RefractionTable::default_wavelengths_nm() {
  std::vector<double> l;
  for (int i = 380; i <= 780; i += 20) l.push_back(i);
  return l;
}

RefractionTable::RefractionTable(double observer_altitude_m, const Options& o)
    : observer_altitude_m_(observer_altitude_m), wavelengths_(o.wavelengths_nm) {
  if (wavelengths_.empty() || o.elevation_nodes < 4)
    throw std::invalid_argument("RefractionTable: need a wavelength and 4 elevation nodes");
  const double r0 = o.planet_radius_m + std::max(0.0, observer_altitude_m);
  const int n = o.elevation_nodes;
  for (double lambda : wavelengths_) {
    const auto shells = RefractiveShells::from_profile(
        us76_refractivity_profile(lambda, o.planet_radius_m, o.top_altitude_m), o.max_refractivity_step);
    auto refraction = [&](double elevation_deg) {
      const auto ray = trace_refracted_ray(shells, r0, 90.0 - elevation_deg, false);
      return ray.outcome == RefractedRay::Outcome::kEscaped ? ray.bending_rad * kRadToDeg : 0.0;
    };
    Column c;
    const double top = shells.top_radius_m();
    c.observer_s = r0 >= top ? r0 : shells.index_at(shells.shell_at(r0), r0) * r0;
    c.k_min = shells.index(0) * shells.ground_radius_m();
    c.k_max = std::min(c.observer_s, top);
    // cos(e) = k / (n0 r0) for e <= 0.
    c.lowest_elevation_deg = -std::acos(std::min(1.0, c.k_min / c.observer_s)) * kRadToDeg;
    c.horizon_elevation_deg = -std::acos(std::min(1.0, c.k_max / c.observer_s)) * kRadToDeg;
    for (int j = 0; j < n; ++j) {
      // The first node sits just off the ground-grazing ray so that rounding
      // cannot send it into the ground (1e-9 deg, far below the table's accuracy).
      const double e = c.lowest_elevation_deg + (c.horizon_elevation_deg - c.lowest_elevation_deg) * j / (n - 1);
      c.below_deg.push_back(c.horizon_elevation_deg > c.lowest_elevation_deg ? refraction(j == 0 ? e + 1e-9 : e)
                                                                              : 0.0);
    }
    for (int j = 0; j < n; ++j) {
      const double u = double(j) / (n - 1);
      const double e = c.horizon_elevation_deg + (90.0 - c.horizon_elevation_deg) * u * u;
      c.above_deg.push_back(j + 1 == n ? 0.0 : refraction(e));
    }
    columns_.push_back(std::move(c));
  }
}

double RefractionTable::refraction_in_column(const Column& c, double apparent_deg) const {
  if (apparent_deg < c.horizon_elevation_deg) {
    const double x = (apparent_deg - c.lowest_elevation_deg) / (c.horizon_elevation_deg - c.lowest_elevation_deg) *
                     (c.below_deg.size() - 1);
    return catmull_rom(c.below_deg, std::clamp(x, 0.0, double(c.below_deg.size() - 1)));
  }
  const double u = std::sqrt((apparent_deg - c.horizon_elevation_deg) / (90.0 - c.horizon_elevation_deg));
  return catmull_rom(c.above_deg, u * (c.above_deg.size() - 1));
}

// Linear in 1 / lambda^2: Ciddor's refractivity is k1 / (k0 - s^2) + ..., close
// to linear in s^2 = 1 / lambda^2 over the visible.
void RefractionTable::bracket(double lambda_nm, int& i0, int& i1, double& w) const {
  const int n = static_cast<int>(wavelengths_.size());
  if (n == 1 || lambda_nm <= wavelengths_.front()) {
    i0 = i1 = 0;
    w = 0.0;
    return;
  }
  if (lambda_nm >= wavelengths_.back()) {
    i0 = i1 = n - 1;
    w = 0.0;
    return;
  }
  i1 = static_cast<int>(std::upper_bound(wavelengths_.begin(), wavelengths_.end(), lambda_nm) - wavelengths_.begin());
  i0 = i1 - 1;
  auto s2 = [](double l) { return 1.0 / (l * l); };
  w = (s2(lambda_nm) - s2(wavelengths_[i0])) / (s2(wavelengths_[i1]) - s2(wavelengths_[i0]));
}

double RefractionTable::lowest_apparent_elevation_deg(double lambda_nm) const {
  int i0, i1;
  double w;
  bracket(lambda_nm, i0, i1, w);
  return std::max(columns_[i0].lowest_elevation_deg, columns_[i1].lowest_elevation_deg);
}

std::optional<double> RefractionTable::refraction_interpolated(double apparent_deg, double lambda_nm) const {
  if (!(apparent_deg >= lowest_apparent_elevation_deg(lambda_nm)) || apparent_deg > 90.0) return std::nullopt;
  int i0, i1;
  double w;
  bracket(lambda_nm, i0, i1, w);
  return (1.0 - w) * refraction_in_column(columns_[i0], apparent_deg) +
         w * refraction_in_column(columns_[i1], apparent_deg);
}

std::optional<double> RefractionTable::refraction_deg(double apparent_deg, double lambda_nm) const {
  return refraction_interpolated(apparent_deg, lambda_nm);
}

std::optional<double> RefractionTable::true_elevation_deg(double apparent_deg, double lambda_nm) const {
  const auto R = refraction_interpolated(apparent_deg, lambda_nm);
  if (!R) return std::nullopt;
  return apparent_deg - *R;
}

// The true elevation e - R(e) increases with the apparent one (R falls as e
// rises, in US76 without ducts), so bisection on e finds the inverse.
std::optional<double> RefractionTable::apparent_elevation_deg(double true_deg, double lambda_nm) const {
  double lo = lowest_apparent_elevation_deg(lambda_nm), hi = 90.0;
  const auto lowest_true = true_elevation_deg(lo, lambda_nm);
  if (!lowest_true || true_deg < *lowest_true || true_deg > 90.0) return std::nullopt;
  for (int i = 0; i < 80 && hi - lo > 1e-13; ++i) {
    const double mid = 0.5 * (lo + hi);
    (*true_elevation_deg(mid, lambda_nm) < true_deg ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace skyfarm
