#include "common/material/smooth_reflector.h"

#include <cmath>
#include <stdexcept>

#include "common/material/fresnel.h"

namespace skyfarm::material {

SmoothReflector SmoothReflector::dielectric(double eta) {
  if (!(eta > 0.0) || !std::isfinite(eta)) throw std::invalid_argument("SmoothReflector: eta must be > 0");
  return SmoothReflector(ConductorFresnel::mirror(), eta, true);
}

double SmoothReflector::reflectance(double cos_theta) const {
  return is_dielectric_ ? fresnel_dielectric(cos_theta, eta_) : fresnel_.reflectance(cos_theta);
}

// The mirror of wo about the macro normal, +z.
std::optional<BsdfSample> SmoothReflector::sample(const glm::dvec3& wo, double, const glm::dvec2&,
                                                  RandomSequence&) const {
  if (!(wo.z > 0.0)) return std::nullopt;
  const double F = reflectance(wo.z);
  if (!(F >= 0.0) || !std::isfinite(F)) return std::nullopt;
  return BsdfSample{{-wo.x, -wo.y, wo.z}, F, 1.0, kBsdfReflection | kBsdfSpecular};
}

}  // namespace skyfarm::material
