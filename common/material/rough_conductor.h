// Single-bounce rough conductor: the Cook-Torrance microfacet BRDF with
// Smith's height-correlated shadowing-masking (light reflects once on the
// microsurface; what would bounce again is lost).
//
// Parameters
//   distribution  the microfacet distribution (GGX or Beckmann, anisotropic).
//   fresnel       the facets' reflectance (complex index n + i k, or a
//                 perfect mirror).
//
// Reflection only (both directions above the macro surface).  sample()
// draws the visible normal from wo and mirrors wo about it, so its value is
// F G2 / G1(wo) <= 1.
#pragma once

#include "common/material/bsdf.h"
#include "common/material/conductor_fresnel.h"
#include "common/material/microfacet_distribution.h"

namespace skyfarm::material {

class RoughConductor final : public Bsdf {
 public:
  RoughConductor(const MicrofacetDistribution& distribution, ConductorFresnel fresnel)
      : distribution_(distribution), fresnel_(fresnel) {}

  std::uint32_t flags() const override { return kBsdfReflection | kBsdfGlossy; }
  bool stochastic() const override { return false; }
  double f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence& rng) const override;
  std::optional<BsdfSample> sample(const glm::dvec3& wo, double uc, const glm::dvec2& u,
                                   RandomSequence& rng) const override;
  double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const override;

 private:
  MicrofacetDistribution distribution_;
  ConductorFresnel fresnel_;
};

}  // namespace skyfarm::material
