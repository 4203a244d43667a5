#include "common/material/multiple_bounce_bsdf.h"

#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "common/material/direction_sampling.h"

namespace skyfarm::material {

namespace {

// The dielectric lobe of a non-dielectric facet is never used; any valid
// index builds it.
double lobe_eta(const Facet& facet) { return facet.kind == FacetKind::dielectric ? facet.eta : 1.5; }

}  // namespace

MultipleBounceBsdf::MultipleBounceBsdf(const MicrofacetDistribution& distribution, Facet facet,
                                       HeightCorrelation correlation, double cosine_share)
    : walk_(distribution, facet, correlation),
      dielectric_lobe_(distribution, lobe_eta(facet), TransportMode::radiance),
      cosine_share_(facet.kind == FacetKind::diffuse ? 1.0 : cosine_share) {
  if (!(cosine_share >= 0.0 && cosine_share < 1.0)) {
    throw std::invalid_argument("MultipleBounceBsdf: cosine_share outside [0, 1)");
  }
}

std::uint32_t MultipleBounceBsdf::flags() const {
  switch (walk_.facet().kind) {
    case FacetKind::conductor:
      return kBsdfReflection | kBsdfGlossy;
    case FacetKind::diffuse:
      return kBsdfReflection | kBsdfDiffuse;
    case FacetKind::dielectric:
      return kBsdfReflection | kBsdfTransmission | kBsdfGlossy;
  }
  return 0;
}

double MultipleBounceBsdf::f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence& rng) const {
  if (wo.z == 0.0) return 0.0;
  const double value = walk_.estimate_bidirectional(wi, wo, rng) / std::abs(wo.z);
  return std::isfinite(value) ? value : 0.0;
}

// The single-bounce lobe's proposal density: the mirror of wo about a
// visible normal (Walter et al. 2007, eq. 14), or the dielectric's.
double MultipleBounceBsdf::lobe_pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  switch (walk_.facet().kind) {
    case FacetKind::conductor: {
      if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
      const glm::dvec3 sum = wo + wi;
      const double length = glm::length(sum);
      if (!(length > 0.0)) return 0.0;
      const glm::dvec3 wh = sum / length;
      const double cos_oh = glm::dot(wo, wh);
      if (cos_oh <= 0.0) return 0.0;
      const double pdf = walk_.distribution().visible_normal_pdf(wo, wh) / (4.0 * cos_oh);
      return std::isfinite(pdf) ? pdf : 0.0;
    }
    case FacetKind::dielectric:
      return dielectric_lobe_.pdf(wo, wi);
    case FacetKind::diffuse:
      return 0.0;
  }
  return 0.0;
}

// Cosine-weighted on the reflection side; a dielectric splits the share
// between both sides.
double MultipleBounceBsdf::cosine_pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (walk_.facet().kind == FacetKind::dielectric) return 0.5 * std::abs(wi.z) / kBsdfPi;
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  return wi.z / kBsdfPi;
}

double MultipleBounceBsdf::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (wo.z == 0.0 || wi.z == 0.0) return 0.0;
  return cosine_share_ * cosine_pdf(wo, wi) + (1.0 - cosine_share_) * lobe_pdf(wo, wi);
}

std::optional<glm::dvec3> MultipleBounceBsdf::propose(const glm::dvec3& wo, double uc, const glm::dvec2& u) const {
  const FacetKind kind = walk_.facet().kind;
  if (wo.z == 0.0 || (kind != FacetKind::dielectric && wo.z < 0.0)) return std::nullopt;
  glm::dvec3 wi;
  if (uc < cosine_share_) {
    const double side = uc / cosine_share_;
    wi = sample_cosine_around({0.0, 0.0, 1.0}, u);
    if (kind == FacetKind::dielectric && side >= 0.5) wi.z = -wi.z;
  } else {
    const double uc_lobe = (uc - cosine_share_) / (1.0 - cosine_share_);
    if (kind == FacetKind::conductor) {
      const glm::dvec3 wh = walk_.distribution().sample_visible_normal(wo, u);
      wi = reflect_about(wo, wh);
    } else {
      RandomSequence unused(0);  // the dielectric's proposal draws nothing more
      const std::optional<BsdfSample> s = dielectric_lobe_.sample(wo, uc_lobe, u, unused);
      if (!s) return std::nullopt;
      wi = s->wi;
    }
  }
  if (wi.z == 0.0 || (kind != FacetKind::dielectric && wi.z < 0.0)) return std::nullopt;
  if (!(pdf(wo, wi) > 0.0)) return std::nullopt;
  return wi;
}

std::optional<BsdfSample> MultipleBounceBsdf::sample(const glm::dvec3& wo, double uc, const glm::dvec2& u,
                                                     RandomSequence& rng) const {
  const std::optional<glm::dvec3> proposed = propose(wo, uc, u);
  if (!proposed) return std::nullopt;
  const glm::dvec3 wi = *proposed;
  const double pdf = this->pdf(wo, wi);
  if (!std::isfinite(pdf)) return std::nullopt;
  const double value = f(wo, wi, rng) * std::abs(wi.z) / pdf;
  std::uint32_t lobe = (wi.z > 0.0) == (wo.z > 0.0) ? kBsdfReflection : kBsdfTransmission;
  lobe |= walk_.facet().kind == FacetKind::diffuse ? kBsdfDiffuse : kBsdfGlossy;
  return BsdfSample{wi, value, pdf, lobe};
}

}  // namespace skyfarm::material
