// Single-bounce rough dielectric interface: microfacet reflection and
// refraction (Walter et al. 2007, "Microfacet models for refraction through
// rough surfaces") with Smith's height-correlated shadowing-masking.
//
// Parameters
//   distribution  the microfacet distribution (GGX or Beckmann, anisotropic).
//   eta           n_inside / n_outside > 0, != 1 (glass in air 1.5).  The
//                 inside is below the macro surface (z < 0).
//   transport     TransportMode::radiance (camera paths: the transmitted
//                 value carries the (n_wo / n_wi)^2 radiance compression) or
//                 ::importance (light paths, and the energy balance: the
//                 transmitted flux fraction is integral f |wi.z| dwi).
//
// wo may be on either side; a wo below the macro surface sees the surface
// from the inside (the frame is mirrored in z and the relative index
// inverted, so the formulas below are written for wo above).  Total internal
// reflection is handled by the Fresnel term (it is 1 there).
#pragma once

#include "common/material/bsdf.h"
#include "common/material/microfacet_distribution.h"

namespace skyfarm::material {

enum class TransportMode { radiance, importance };

class RoughDielectric final : public Bsdf {
 public:
  RoughDielectric(const MicrofacetDistribution& distribution, double eta,
                  TransportMode transport = TransportMode::radiance);

  std::uint32_t flags() const override { return kBsdfReflection | kBsdfTransmission | kBsdfGlossy; }
  bool stochastic() const override { return false; }
  double f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence& rng) const override;
  std::optional<BsdfSample> sample(const glm::dvec3& wo, double uc, const glm::dvec2& u,
                                   RandomSequence& rng) const override;
  double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const override;

 private:
  // The half vector of (wo, wi) with wo above (wh.z > 0), and the relative
  // index seen from wo; false when the pair has no facet (back-facing).
  bool half_vector(const glm::dvec3& wo, const glm::dvec3& wi, double eta, glm::dvec3& wh) const;
  double f_above(const glm::dvec3& wo, const glm::dvec3& wi, double eta) const;
  double pdf_above(const glm::dvec3& wo, const glm::dvec3& wi, double eta) const;

  MicrofacetDistribution distribution_;
  double eta_;
  TransportMode transport_;
};

}  // namespace skyfarm::material
