#include "common/atmosphere/refraction_integral.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

struct Medium {
  const RefractivityProfile& profile;
  double n(double r) const {
    const double h = r - profile.planet_radius_m;
    return h >= profile.top_altitude_m ? 1.0 : 1.0 + profile.refractivity(h);
  }
  // r n'(r), centred difference over 0.5 m (the profile is smooth within layers).
  double r_dn(double r) const {
    constexpr double d = 0.25;
    const double h = r - profile.planet_radius_m;
    if (h >= profile.top_altitude_m) return 0.0;
    const double lo = std::max(h - d, 0.0), hi = std::min(h + d, profile.top_altitude_m);
    return r * (profile.refractivity(hi) - profile.refractivity(lo)) / (hi - lo);
  }
  // Radius on [lo, hi] where n(r) r = target (n r increases with r).
  double radius_where(double target, double lo, double hi) const {
    for (int i = 0; i < 60 && hi - lo > 1e-7; ++i) {
      const double mid = 0.5 * (lo + hi);
      (n(mid) * mid < target ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
};

// Bending of an ascending branch from radius r_low (zenith z_low there) to the top,
// Simpson's rule in z on pieces split at the kinks.
double ascending_bending(const Medium& m, double k, double r_low, double z_low, const std::vector<double>& kinks,
                         int intervals) {
  const double top = m.profile.planet_radius_m + m.profile.top_altitude_m;
  if (r_low >= top) return 0.0;
  auto z_at = [&](double r) { return std::asin(std::min(1.0, k / (m.n(r) * r))); };
  std::vector<double> radii{r_low};
  for (double h : kinks) {
    const double r = m.profile.planet_radius_m + h;
    if (r > r_low && r < top) radii.push_back(r);
  }
  radii.push_back(top);
  double total = 0.0;
  for (std::size_t piece = 0; piece + 1 < radii.size(); ++piece) {
    const double ra = radii[piece], rb = radii[piece + 1];
    const double za = piece == 0 ? z_low : z_at(ra), zb = z_at(rb);
    auto integrand = [&](double z) {
      const double r = (z >= za) ? ra : (z <= zb) ? rb : m.radius_where(k / std::sin(z), ra, rb);
      const double rdn = m.r_dn(r);
      return -rdn / (m.n(r) + rdn);
    };
    const int n = intervals + (intervals & 1);
    const double h = (za - zb) / n;
    double s = integrand(zb) + integrand(za);
    for (int i = 1; i < n; ++i) s += (i & 1 ? 4.0 : 2.0) * integrand(zb + i * h);
    total += s * h / 3.0;
  }
  return total;
}

}  // namespace

std::vector<double> us76_layer_altitudes_m() {
  // Geopotential 11, 20, 32, 47, 51, 71 km' as geometric altitude (r0 H / (r0 - H)), and 86 km.
  std::vector<double> z;
  for (double H : {11000.0, 20000.0, 32000.0, 47000.0, 51000.0, 71000.0}) z.push_back(6356766.0 * H / (6356766.0 - H));
  z.push_back(86000.0);
  return z;
}

double refraction_integral(const RefractivityProfile& profile, double observer_altitude_m, double zenith_deg,
                           const std::vector<double>& kink_altitudes_m, int intervals_per_piece) {
  const Medium m{profile};
  const double r0 = profile.planet_radius_m + observer_altitude_m;
  const double z0 = zenith_deg * kDegToRad;
  const double k = m.n(r0) * r0 * std::sin(z0);
  if (z0 <= 0.5 * kPi) return ascending_bending(m, k, r0, z0, kink_altitudes_m, intervals_per_piece);
  // Descending first: the tangent radius solves n(r) r = k below the observer.
  const double ground = profile.planet_radius_m;
  if (m.n(ground) * ground >= k) return std::numeric_limits<double>::quiet_NaN();
  const double r_t = m.radius_where(k, ground, r0);
  const double down = ascending_bending(m, k, r_t, 0.5 * kPi, kink_altitudes_m, intervals_per_piece) -
                      ascending_bending(m, k, r0, kPi - z0, kink_altitudes_m, intervals_per_piece);
  return down + ascending_bending(m, k, r_t, 0.5 * kPi, kink_altitudes_m, intervals_per_piece);
}

}  // namespace skyfarm
