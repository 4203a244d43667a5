#include "common/sun/sun.h"

#include <cmath>
#include <glm/geometric.hpp>
#include <stdexcept>

#include "common/core/constants.h"
#include "common/geometry/ray.h"
#include "common/sun/solar_position.h"
#include "common/sun/solar_spectrum.h"

namespace skyfarm {

Sun::Sun(double zenith_deg, double azimuth_deg, double angular_radius_deg, PiecewiseLinear irradiance)
    : zenith_deg_(zenith_deg),
      azimuth_deg_(azimuth_deg),
      alpha_(angular_radius_deg * kDegToRad),
      cos_alpha_(std::cos(angular_radius_deg * kDegToRad)),
      direction_(direction_from_zenith_azimuth(zenith_deg * kDegToRad, azimuth_deg * kDegToRad)),
      frame_(direction_),
      irradiance_(std::move(irradiance)) {
  if (!(angular_radius_deg >= 0.0) || angular_radius_deg >= 90.0)
    throw std::invalid_argument("sun: angular radius must be in [0, 90) degrees");
  // Each as the expression it replaces computed it, so the values are the same bits.
  const double s = std::sin(alpha_);
  pi_sin2_alpha_ = kPi * s * s;
  const double half = std::sin(0.5 * alpha_);
  contains_bound_ = 2.0 * half * half;
  solid_angle_ = uniform_cone_solid_angle(alpha_);
  cone_height_ = uniform_cone_height(alpha_);
}

Sun Sun::from_spec(const SunSpec& spec, const Location& where, const std::optional<UtcInstant>& time) {
  const bool angles = spec.zenith_deg && spec.azimuth_deg;
  if (!angles && !time) throw std::invalid_argument("sun: needs a time or both sun.zenith_deg and sun.azimuth_deg");
  double zenith = 0.0, azimuth = 0.0, distance = 1.0;
  if (time) {
    const SolarPosition p = solar_position(where, *time);
    zenith = p.zenith_deg;
    azimuth = p.azimuth_deg;
    distance = p.earth_sun_distance_au;
  }
  if (angles) {
    zenith = *spec.zenith_deg;
    azimuth = *spec.azimuth_deg;
  }
  // AM0 is given at 1 AU; irradiance falls as 1 / R^2.  A request's own table is used as given.
  PiecewiseLinear E;
  if (spec.irradiance) {
    E = PiecewiseLinear(spec.irradiance->wavelengths_nm, spec.irradiance->values, PiecewiseLinear::Outside::kZero,
                        "sun.irradiance");
  } else {
    const auto& am0 = am0_irradiance();
    std::vector<double> x(am0.x().begin(), am0.x().end()), y(am0.y().begin(), am0.y().end());
    for (double& v : y) v /= distance * distance;
    E = PiecewiseLinear(std::move(x), std::move(y), PiecewiseLinear::Outside::kZero, "AM0");
  }
  Sun sun(zenith, azimuth, spec.angular_radius_deg, std::move(E));
  sun.distance_au_ = spec.irradiance ? 1.0 : distance;
  return sun;
}

double Sun::solid_angle_sr() const { return solid_angle_; }

// L = E / (pi sin^2 alpha): see the header.
double Sun::radiance(double lambda_nm) const {
  if (is_point()) return irradiance(lambda_nm);
  return irradiance(lambda_nm) / pi_sin2_alpha_;
}

// cos(angle to the centre) >= cos(alpha), compared as 1 - cos to keep
// precision for a 0.27-degree disk: 1 - w.d = |w - d|^2 / 2 for unit vectors.
bool Sun::contains(const glm::dvec3& w) const {
  if (is_point()) return false;
  const glm::dvec3 diff = w - direction_;
  const double one_minus_cos = 0.5 * glm::dot(diff, diff);
  return one_minus_cos <= contains_bound_;
}

glm::dvec3 Sun::sample_direction(double u1, double u2, double* pdf) const {
  if (is_point()) {
    *pdf = 1.0;
    return direction_;
  }
  *pdf = 1.0 / solid_angle_sr();
  return glm::normalize(frame_.to_world(square_to_uniform_cone_of_height({u1, u2}, cone_height_)));
}

double Sun::pdf(const glm::dvec3& w) const { return contains(w) ? 1.0 / solid_angle_sr() : 0.0; }

}  // namespace skyfarm
