#include "common/geometry/ray.h"

#include <cmath>

#include "common/core/constants.h"
#include "common/core/math.h"

namespace skyfarm {

glm::dvec3 direction_from_zenith_azimuth(double zenith_rad, double azimuth_rad) {
  const double s = std::sin(zenith_rad);
  return {s * std::sin(azimuth_rad), s * std::cos(azimuth_rad), std::cos(zenith_rad)};
}

// atan2 of the horizontal components for the azimuth; the zenith from atan2
// of (horizontal length, z), accurate at both poles unlike acos(z).
void zenith_azimuth_from_direction(const glm::dvec3& d, double* zenith_rad, double* azimuth_rad) {
  const double horizontal = std::sqrt(d.x * d.x + d.y * d.y);
  *zenith_rad = std::atan2(horizontal, d.z);
  double a = std::atan2(d.x, d.y);
  if (a < 0.0) a += 2.0 * kPi;
  *azimuth_rad = (a >= 2.0 * kPi) ? 0.0 : a;
}

}  // namespace skyfarm
