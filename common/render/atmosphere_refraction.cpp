#include "common/render/atmosphere_refraction.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <utility>

#include <glm/geometric.hpp>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

// Ciddor's formula holds from 300 nm to 1690 nm; beyond the nodes the
// nearest one is used.
constexpr double kFirstShell_nm = 300.0;
constexpr double kLastShell_nm = 1100.0;
// Altitudes of the elevation tables, m: dense near the ground, where the
// horizon's dip (~sqrt(h)) and the refraction change fastest.
constexpr double kTableAltitudes_m[] = {0,     50,    150,   300,   600,   1000,  1500,  2200,
                                        3000,  4000,  5500,  7000,  9000,  11000, 14000, 18000,
                                        23000, 30000, 40000, 55000, 75000};
// Half-width of the central difference of the elevation map, degrees.
constexpr double kDerivativeStep_deg = 1e-3;

}  // namespace

AtmosphereRefraction::AtmosphereRefraction(double planet_radius_m, double top_altitude_m)
    : planet_radius_m_(planet_radius_m), top_altitude_m_(top_altitude_m), first_shell_nm_(kFirstShell_nm) {
  const double thickness = std::max(kMaxThickness_m, top_altitude_m / 40.0);
  for (double lambda = kFirstShell_nm; lambda <= kLastShell_nm + 1e-9; lambda += kShellStep_nm)
    shells_.push_back(RefractiveShells::from_profile(us76_refractivity_profile(lambda, planet_radius_m, top_altitude_m),
                                                     kMaxRefractivityStep, thickness));
  RefractionTable::Options options;
  options.wavelengths_nm = {360.0, 420.0, 500.0, 600.0, 720.0, 830.0};
  options.elevation_nodes = 96;
  options.max_refractivity_step = kMaxRefractivityStep;
  options.planet_radius_m = planet_radius_m;
  options.top_altitude_m = top_altitude_m;
  for (const double h : kTableAltitudes_m)
    if (h < top_altitude_m) altitudes_m_.push_back(h);
  altitudes_m_.push_back(top_altitude_m);
  tables_.reserve(altitudes_m_.size());
  for (const double h : altitudes_m_) tables_.emplace_back(h, options);
}

std::shared_ptr<const AtmosphereRefraction> AtmosphereRefraction::shared(double planet_radius_m,
                                                                         double top_altitude_m) {
  static std::mutex mutex;
  static std::map<std::pair<double, double>, std::shared_ptr<const AtmosphereRefraction>> models;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& model = models[{planet_radius_m, top_altitude_m}];
  if (!model) model = std::make_shared<const AtmosphereRefraction>(planet_radius_m, top_altitude_m);
  return model;
}

const RefractiveShells& AtmosphereRefraction::shells(double lambda_nm) const {
  const double x = std::round((lambda_nm - first_shell_nm_) / kShellStep_nm);
  const auto i = static_cast<std::size_t>(std::clamp(x, 0.0, static_cast<double>(shells_.size() - 1)));
  return shells_[i];
}

void AtmosphereRefraction::bracket(double altitude_m, int* i0, double* w) const {
  const auto it = std::upper_bound(altitudes_m_.begin(), altitudes_m_.end(), altitude_m);
  const int n = static_cast<int>(altitudes_m_.size());
  const int i = std::clamp(static_cast<int>(it - altitudes_m_.begin()) - 1, 0, n - 2);
  *i0 = i;
  *w = std::clamp((altitude_m - altitudes_m_[i]) / (altitudes_m_[i + 1] - altitudes_m_[i]), 0.0, 1.0);
}

std::optional<double> AtmosphereRefraction::true_elevation_deg(double altitude_m, double apparent_deg,
                                                               double lambda_nm) const {
  int i;
  double w;
  bracket(altitude_m, &i, &w);
  const auto a = tables_[i].true_elevation_deg(apparent_deg, lambda_nm);
  const auto b = tables_[i + 1].true_elevation_deg(apparent_deg, lambda_nm);
  if (!a || !b) return std::nullopt;
  return (1.0 - w) * *a + w * *b;
}

// Newton's method on the interpolated map (increasing in e without ducts, as
// each table's is), safeguarded by a bracket from the lowest apparent
// elevation both nodes trace to 90 deg: a step that leaves the bracket is a
// bisection instead.  From the guess e = t + R(t) it takes ~3 steps (two
// look-ups each) where plain bisection took ~33, and it stops where the map
// returns the true elevation to 1e-10 deg (or the bracket is 1e-9 deg wide).
std::optional<double> AtmosphereRefraction::apparent_elevation_deg(double altitude_m, double true_deg,
                                                                   double lambda_nm) const {
  constexpr double kStep_deg = 1e-6;
  int i;
  double w;
  bracket(altitude_m, &i, &w);
  double lo = std::max(tables_[i].lowest_apparent_elevation_deg(lambda_nm),
                       tables_[i + 1].lowest_apparent_elevation_deg(lambda_nm));
  double hi = 90.0;
  const auto lowest = true_elevation_deg(altitude_m, lo, lambda_nm);
  if (!lowest || true_deg < *lowest) return std::nullopt;
  if (true_deg >= 90.0) return 90.0;
  const auto guess = tables_[i].refraction_deg(std::max(true_deg, lo), lambda_nm);
  double e = std::clamp(true_deg + (guess ? *guess : 0.0), lo, hi);
  for (int k = 0; k < 60 && hi - lo > 1e-9; ++k) {
    const auto t = true_elevation_deg(altitude_m, e, lambda_nm);
    if (!t) {  // (not inside the bracket but for round-off) bisect
      lo = e;
      e = 0.5 * (lo + hi);
      continue;
    }
    const double miss = *t - true_deg;
    if (std::abs(miss) < 1e-10) return e;
    (miss < 0.0 ? lo : hi) = e;
    const double e_step = std::min(hi, e + kStep_deg);
    const auto t_step = true_elevation_deg(altitude_m, e_step, lambda_nm);
    const double slope = t_step && e_step > e ? (*t_step - *t) / (e_step - e) : 0.0;
    const double next = slope > 0.0 ? e - miss / slope : 0.5 * (lo + hi);
    e = next > lo && next < hi ? next : 0.5 * (lo + hi);
  }
  return e;
}

double AtmosphereRefraction::solid_angle_ratio(double altitude_m, double apparent_deg, double lambda_nm) const {
  // de_t / de_a by a central difference (one-sided at the ends of the tables).
  double a = apparent_deg - kDerivativeStep_deg, b = std::min(90.0, apparent_deg + kDerivativeStep_deg);
  auto ta = true_elevation_deg(altitude_m, a, lambda_nm);
  if (!ta) {
    a = apparent_deg;
    ta = true_elevation_deg(altitude_m, a, lambda_nm);
  }
  const auto tb = true_elevation_deg(altitude_m, b, lambda_nm);
  const auto te = true_elevation_deg(altitude_m, apparent_deg, lambda_nm);
  if (!ta || !tb || !te || !(b > a)) return 0.0;
  const double dt_da = (*tb - *ta) / (b - a);
  const double cos_true = std::cos(*te * kDegToRad);
  if (!(dt_da > 0.0) || !(cos_true > 1e-12)) return 1.0;  // at the zenith: no bending
  return std::cos(apparent_deg * kDegToRad) / (cos_true * dt_da);
}

std::optional<AtmosphereRefraction::Apparent> AtmosphereRefraction::apparent_direction(const glm::dvec3& p,
                                                                                       const glm::dvec3& s,
                                                                                       double lambda_nm) const {
  const double r = glm::length(p);
  const glm::dvec3 up = p / r;
  const double sin_e = std::clamp(glm::dot(s, up), -1.0, 1.0);
  glm::dvec3 horizontal = s - sin_e * up;
  const double length = glm::length(horizontal);
  if (!(length > 1e-12)) return Apparent{s, 1.0};  // overhead (or underfoot): no bending
  horizontal /= length;
  const double altitude = r - planet_radius_m_;
  const double e_true = std::atan2(sin_e, length) * kRadToDeg;
  const auto e_app = apparent_elevation_deg(altitude, e_true, lambda_nm);
  if (!e_app) return std::nullopt;
  const double ratio = solid_angle_ratio(altitude, *e_app, lambda_nm);
  if (!(ratio > 0.0)) return std::nullopt;
  const double e = *e_app * kDegToRad;
  return Apparent{std::cos(e) * horizontal + std::sin(e) * up, ratio};
}

double AtmosphereRefraction::solid_angle_ratio_at(const glm::dvec3& p, const glm::dvec3& d, double lambda_nm) const {
  const double r = glm::length(p);
  const double sin_e = std::clamp(glm::dot(d, p / r), -1.0, 1.0);
  return solid_angle_ratio(r - planet_radius_m_, std::asin(sin_e) * kRadToDeg, lambda_nm);
}

}  // namespace skyfarm
