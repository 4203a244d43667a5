#include "common/material/rough_dielectric.h"

#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "common/material/direction_sampling.h"
#include "common/material/fresnel.h"
#include "common/material/smith_full_sphere.h"

namespace skyfarm::material {

namespace {

glm::dvec3 mirror_z(const glm::dvec3& w) { return {w.x, w.y, -w.z}; }

}  // namespace

RoughDielectric::RoughDielectric(const MicrofacetDistribution& distribution, double eta, TransportMode transport)
    : distribution_(distribution), eta_(eta), transport_(transport) {
  if (!(eta > 0.0) || !std::isfinite(eta) || eta == 1.0) {
    throw std::invalid_argument("RoughDielectric: eta must be finite, > 0 and != 1");
  }
}

// Walter et al. 2007, eq. 13 (reflection) and eq. 16 (transmission, with
// eta = n_wi / n_wo the index of wi's side over wo's):
//   wh_r = (wo + wi) / |wo + wi|,   wh_t = -(wo + eta wi) / |wo + eta wi|,
// oriented to the side of wo (wh.z > 0 for wo above).  A transmission pair
// needs wo in front of the facet and wi behind it.
bool RoughDielectric::half_vector(const glm::dvec3& wo, const glm::dvec3& wi, double eta,
                                  glm::dvec3& wh) const {
  const bool reflect = wi.z > 0.0;
  const glm::dvec3 sum = reflect ? wo + wi : wo + eta * wi;
  const double length = glm::length(sum);
  if (!(length > 0.0)) return false;
  wh = sum / length;
  if (wh.z < 0.0) wh = -wh;
  if (wh.z <= 0.0) return false;
  if (glm::dot(wo, wh) <= 0.0) return false;
  if (reflect ? glm::dot(wi, wh) <= 0.0 : glm::dot(wi, wh) >= 0.0) return false;
  return true;
}

// wo above the macro surface, eta = n(wi side of a transmission) / n(wo side).
// Walter et al. 2007, eq. 20 (reflection) and eq. 21 (transmission):
//   f_r = F D G2 / (4 |wo.z| |wi.z|),
//   f_t = |wi.wh| |wo.wh| / (|wi.z| |wo.z|) (1 - F) D G2 eta^2 / (wo.wh + eta wi.wh)^2
// in importance (flux) form, which integrates against |wi.z| to the
// transmitted fraction; the radiance form divides by eta^2 (pbrt-v4's
// TransportMode::Radiance: radiance is compressed by (n_wo / n_wi)^2).
double RoughDielectric::f_above(const glm::dvec3& wo, const glm::dvec3& wi, double eta) const {
  if (wi.z == 0.0) return 0.0;
  glm::dvec3 wh;
  if (!half_vector(wo, wi, eta, wh)) return 0.0;
  const double cos_oh = glm::dot(wo, wh);
  const double fresnel = fresnel_dielectric(cos_oh, eta);
  const double g2 = g2_full_sphere(distribution_, glm::dvec3(wi.x, wi.y, std::abs(wi.z)), wo);
  const double d = distribution_.D(wh);
  double value = 0.0;
  if (wi.z > 0.0) {
    value = d * fresnel * g2 / (4.0 * wo.z * wi.z);
  } else {
    const double cos_ih = glm::dot(wi, wh);
    const double denom = cos_oh + eta * cos_ih;
    value = std::abs(cos_ih * cos_oh / (wi.z * wo.z)) * (1.0 - fresnel) * d * g2 * eta * eta / (denom * denom);
    if (transport_ == TransportMode::radiance) value /= eta * eta;
  }
  return std::isfinite(value) && value > 0.0 ? value : 0.0;
}

// The proposal: wh ~ D_wo (visible normals), reflect with probability F,
// refract otherwise.  Jacobians: reflection d wh / d wi = 1 / (4 |wo.wh|)
// (Walter et al. 2007, eq. 14); transmission d wh / d wi =
// eta^2 |wi.wh| / (wo.wh + eta wi.wh)^2 (eq. 17).
double RoughDielectric::pdf_above(const glm::dvec3& wo, const glm::dvec3& wi, double eta) const {
  if (wi.z == 0.0) return 0.0;
  glm::dvec3 wh;
  if (!half_vector(wo, wi, eta, wh)) return 0.0;
  const double cos_oh = glm::dot(wo, wh);
  const double fresnel = fresnel_dielectric(cos_oh, eta);
  const double visible = distribution_.visible_normal_pdf(wo, wh);
  double pdf = 0.0;
  if (wi.z > 0.0) {
    pdf = fresnel * visible / (4.0 * cos_oh);
  } else {
    const double cos_ih = glm::dot(wi, wh);
    const double denom = cos_oh + eta * cos_ih;
    pdf = (1.0 - fresnel) * visible * eta * eta * std::abs(cos_ih) / (denom * denom);
  }
  return std::isfinite(pdf) && pdf > 0.0 ? pdf : 0.0;
}

double RoughDielectric::f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence&) const {
  if (wo.z == 0.0) return 0.0;
  if (wo.z > 0.0) return f_above(wo, wi, eta_);
  return f_above(mirror_z(wo), mirror_z(wi), 1.0 / eta_);
}

double RoughDielectric::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (wo.z == 0.0) return 0.0;
  if (wo.z > 0.0) return pdf_above(wo, wi, eta_);
  return pdf_above(mirror_z(wo), mirror_z(wi), 1.0 / eta_);
}

std::optional<BsdfSample> RoughDielectric::sample(const glm::dvec3& wo_in, double uc, const glm::dvec2& u,
                                                  RandomSequence&) const {
  if (wo_in.z == 0.0) return std::nullopt;
  const bool flipped = wo_in.z < 0.0;
  const glm::dvec3 wo = flipped ? mirror_z(wo_in) : wo_in;
  const double eta = flipped ? 1.0 / eta_ : eta_;
  const glm::dvec3 wh = distribution_.sample_visible_normal(wo, u);
  const double cos_oh = glm::dot(wo, wh);
  if (!(cos_oh > 0.0)) return std::nullopt;
  const double fresnel = fresnel_dielectric(cos_oh, eta);
  glm::dvec3 wi;
  std::uint32_t lobe = kBsdfGlossy;
  if (uc < fresnel) {
    wi = reflect_about(wo, wh);
    if (wi.z <= 0.0) return std::nullopt;
    lobe |= kBsdfReflection;
  } else {
    // Snell's law in vector form (pbrt-v4's Refract): the refracted ray
    // leaves along -wo / eta + (cos_i / eta - cos_t) wh.
    const double sin2_t = (1.0 - cos_oh * cos_oh) / (eta * eta);
    if (sin2_t >= 1.0) return std::nullopt;  // only reached by rounding: F = 1 under TIR
    const double cos_t = std::sqrt(1.0 - sin2_t);
    wi = glm::normalize(-wo / eta + (cos_oh / eta - cos_t) * wh);
    if (wi.z >= 0.0) return std::nullopt;
    lobe |= kBsdfTransmission;
  }
  const double pdf = pdf_above(wo, wi, eta);
  const double value = f_above(wo, wi, eta) * std::abs(wi.z);
  if (!(pdf > 0.0)) return std::nullopt;
  return BsdfSample{flipped ? mirror_z(wi) : wi, value / pdf, pdf, lobe};
}

}  // namespace skyfarm::material
