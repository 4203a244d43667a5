// A rough conductor, rough diffuse or rough dielectric BSDF in which light
// bounces any number of times on the microsurface, computed position-free
// (position_free_walk.h): energy that the single-bounce forms lose to
// multiple scattering is kept, so a non-absorbing surface reflects (and
// transmits) everything at any roughness.
//
// Parameters
//   distribution  the microfacet distribution (GGX or Beckmann, anisotropic).
//   facet         Facet::conductor(fresnel), Facet::diffuse(albedo) or
//                 Facet::dielectric(eta); see position_free_walk.h.
//   correlation   HeightCorrelation::correlated (default: the closest to a
//                 surface with heights) or ::uncorrelated (reciprocal).
//   cosine_share  the probability, in [0, 1), with which sample() proposes a
//                 cosine-weighted direction instead of the single-bounce
//                 lobe (default 0.5): the multiple-bounce lobe is broad,
//                 and a sharper proposal gains little while f is noisy.
//
// f() is stochastic: the bidirectional estimator (walks from wi and from wo
// joined at every pair of prefixes, balance-weighted; every facet kind),
// divided by |wo.z|; the value is in the radiance
// convention (light from wi seen from wo), which for the dielectric is what
// conserves energy over wo.  pdf() is the density of sample()'s proposal, a
// mixture of the single-bounce lobe's visible-normal proposal (conductor:
// mirror; dielectric: Fresnel-chosen reflect / refract; diffuse: none) and
// cosine-weighted hemispheres (the dielectric's on both sides, half each).
#pragma once

#include "common/material/bsdf.h"
#include "common/material/position_free_walk.h"
#include "common/material/rough_dielectric.h"

namespace skyfarm::material {

class MultipleBounceBsdf final : public Bsdf {
 public:
  MultipleBounceBsdf(const MicrofacetDistribution& distribution, Facet facet,
                     HeightCorrelation correlation = HeightCorrelation::correlated, double cosine_share = 0.5);

  std::uint32_t flags() const override;
  bool stochastic() const override { return true; }
  double f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence& rng) const override;
  std::optional<BsdfSample> sample(const glm::dvec3& wo, double uc, const glm::dvec2& u,
                                   RandomSequence& rng) const override;
  double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const override;

  // sample()'s proposal alone, without evaluating f: a direction drawn with
  // density pdf(wo, .).  The path tracer proposes once with the hero
  // wavelength's BSDF and evaluates f at every wavelength of the path.
  std::optional<glm::dvec3> propose(const glm::dvec3& wo, double uc, const glm::dvec2& u) const;

  const PositionFreeWalk& walk() const { return walk_; }

 private:
  double lobe_pdf(const glm::dvec3& wo, const glm::dvec3& wi) const;
  double cosine_pdf(const glm::dvec3& wo, const glm::dvec3& wi) const;

  PositionFreeWalk walk_;
  RoughDielectric dielectric_lobe_;  // the dielectric's single-bounce proposal
  double cosine_share_;
};

}  // namespace skyfarm::material
