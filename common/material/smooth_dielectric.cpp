#include "common/material/smooth_dielectric.h"

#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "common/material/fresnel.h"

namespace skyfarm::material {

SmoothDielectric::SmoothDielectric(double eta, TransportMode transport) : eta_(eta), transport_(transport) {
  if (!(eta > 0.0) || !std::isfinite(eta) || eta == 1.0)
    throw std::invalid_argument("SmoothDielectric: eta must be finite, > 0 and != 1");
}

// Reflection about +z; refraction by Snell's law in vector form about the
// normal on wo's side (pbrt-v4's Refract), with the relative index seen from
// wo: eta for wo above, 1 / eta below.
std::optional<SmoothDielectric::Lobe> SmoothDielectric::lobe(const glm::dvec3& wo, bool reflect) const {
  if (wo.z == 0.0) return std::nullopt;
  const double F = fresnel_dielectric(wo.z, eta_);  // a negative cosine inverts eta
  if (reflect) {
    if (!(F > 0.0)) return std::nullopt;
    return Lobe{{-wo.x, -wo.y, wo.z}, F, F};
  }
  const double T = 1.0 - F;
  if (!(T > 0.0)) return std::nullopt;  // total internal reflection
  const double eta = wo.z > 0.0 ? eta_ : 1.0 / eta_;  // n(wi side) / n(wo side)
  const double cos_o = std::abs(wo.z);
  const double sin2_t = (1.0 - cos_o * cos_o) / (eta * eta);
  if (sin2_t >= 1.0) return std::nullopt;
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const glm::dvec3 n(0.0, 0.0, wo.z > 0.0 ? 1.0 : -1.0);
  const glm::dvec3 wi = glm::normalize(-wo / eta + (cos_o / eta - cos_t) * n);
  const double factor = transport_ == TransportMode::radiance ? 1.0 / (eta * eta) : 1.0;
  return Lobe{wi, T * factor, T};
}

std::optional<BsdfSample> SmoothDielectric::sample(const glm::dvec3& wo, double uc, const glm::dvec2&,
                                                   RandomSequence&) const {
  if (wo.z == 0.0) return std::nullopt;
  const bool reflect = uc < fresnel_dielectric(wo.z, eta_);
  const std::optional<Lobe> l = lobe(wo, reflect);
  if (!l) return std::nullopt;
  return BsdfSample{l->wi, l->weight / l->probability, l->probability,
                    (reflect ? kBsdfReflection : kBsdfTransmission) | kBsdfSpecular};
}

}  // namespace skyfarm::material
