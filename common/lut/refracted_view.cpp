#include "common/lut/refracted_view.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

// Shells a little coarser than the reference's (a table costs ~10 ms, not
// ~50): the horizon refraction changes by < 1" (atmosphere_refraction.h).
RefractionTable::Options table_options(double planet_radius_m, double top_altitude_m) {
  RefractionTable::Options o;
  o.elevation_nodes = 128;
  o.max_refractivity_step = 2e-6;
  o.planet_radius_m = planet_radius_m;
  o.top_altitude_m = top_altitude_m;
  return o;
}

constexpr double kReference_nm = 550.0;
constexpr double kShiftFade_deg = 10.0;

// v turned in its vertical plane to elevation e (degrees).
glm::dvec3 with_elevation(const glm::dvec3& v, double e_deg) {
  const double horizontal = std::hypot(v.x, v.y);
  const double e = e_deg * kDegToRad;
  if (!(horizontal > 1e-15)) return v;
  return {v.x / horizontal * std::cos(e), v.y / horizontal * std::cos(e), std::sin(e)};
}

}  // namespace

RefractedView::RefractedView(double observer_altitude_m, double planet_radius_m, double top_altitude_m)
    : table_(std::min(observer_altitude_m, top_altitude_m), table_options(planet_radius_m, top_altitude_m)) {
  const double r = planet_radius_m + std::max(0.0, observer_altitude_m);
  const double geometric_horizon = -std::acos(std::min(1.0, planet_radius_m / r)) * kRadToDeg;
  apparent_horizon_deg_ = table_.lowest_apparent_elevation_deg(kReference_nm);
  horizon_shift_deg_ = geometric_horizon - apparent_horizon_deg_;
}

glm::dvec3 RefractedView::sky_direction(const glm::dvec3& v) const {
  const double e = std::asin(std::clamp(v.z, -1.0, 1.0)) * kRadToDeg;
  const double fade = std::max(0.0, 1.0 - std::abs(e - apparent_horizon_deg_) / kShiftFade_deg);
  if (!(fade > 0.0) || horizon_shift_deg_ == 0.0) return v;
  return with_elevation(v, e + horizon_shift_deg_ * fade);
}

std::optional<glm::dvec3> RefractedView::true_direction(const glm::dvec3& v, double lambda_nm) const {
  const double e = std::asin(std::clamp(v.z, -1.0, 1.0)) * kRadToDeg;
  const auto e_true = table_.true_elevation_deg(e, lambda_nm);
  if (!e_true) return std::nullopt;
  return with_elevation(v, *e_true);
}

std::optional<RefractedView::Apparent> RefractedView::apparent_direction(const glm::dvec3& d,
                                                                       double lambda_nm) const {
  constexpr double kStep_deg = 1e-3;
  const double e = std::asin(std::clamp(d.z, -1.0, 1.0)) * kRadToDeg;
  const auto e_app = table_.apparent_elevation_deg(e, lambda_nm);
  if (!e_app) return std::nullopt;
  const auto below = table_.apparent_elevation_deg(e - kStep_deg, lambda_nm);
  const auto above = table_.apparent_elevation_deg(std::min(90.0, e + kStep_deg), lambda_nm);
  double ratio = 1.0;
  const double cos_e = std::cos(e * kDegToRad);
  if (above && cos_e > 1e-12) {
    const double lo = below ? e - kStep_deg : e, e_lo = below ? *below : *e_app;
    ratio = std::cos(*e_app * kDegToRad) / cos_e * (*above - e_lo) / (std::min(90.0, e + kStep_deg) - lo);
  }
  return Apparent{with_elevation(d, *e_app), ratio};
}

}  // namespace skyfarm
