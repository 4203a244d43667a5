// Single-bounce rough diffuse: a microsurface of Lambertian facets (Heitz and
// Dupuy 2015, "Implementing a simple anisotropic rough diffuse material with
// stochastic evaluation"), light scattering once on it.
//
// Parameters
//   distribution  the microfacet distribution (GGX or Beckmann, anisotropic).
//   albedo        the facets' Lambertian albedo at this wavelength, in [0, 1].
//
// Reflection only.  The BRDF is an integral over the visible normals with no
// closed form, so f() is stochastic: one visible normal per call (an
// unbiased estimate).  sample() proposes cosine-weighted directions (an
// exact, deterministic pdf) and weights them with that estimate.
#pragma once

#include "common/material/bsdf.h"
#include "common/material/microfacet_distribution.h"

namespace skyfarm::material {

class RoughDiffuse final : public Bsdf {
 public:
  RoughDiffuse(const MicrofacetDistribution& distribution, double albedo);

  std::uint32_t flags() const override { return kBsdfReflection | kBsdfDiffuse; }
  bool stochastic() const override { return true; }
  double f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence& rng) const override;
  std::optional<BsdfSample> sample(const glm::dvec3& wo, double uc, const glm::dvec2& u,
                                   RandomSequence& rng) const override;
  double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const override;

 private:
  MicrofacetDistribution distribution_;
  double albedo_;
};

}  // namespace skyfarm::material
