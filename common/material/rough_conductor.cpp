#include "common/material/rough_conductor.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "common/material/direction_sampling.h"
#include "common/material/smith_full_sphere.h"

namespace skyfarm::material {

// Cook and Torrance 1982 with Smith's height-correlated G2 (Heitz 2014,
// "Understanding the masking-shadowing function", eq. 99):
//   f(wo, wi) = D(wh) F(wo . wh) G2(wo, wi) / (4 |wo.z| |wi.z|),
//   wh = (wo + wi) / |wo + wi|.
double RoughConductor::f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence&) const {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  const glm::dvec3 sum = wo + wi;
  const double length = glm::length(sum);
  if (length == 0.0) return 0.0;
  const glm::dvec3 wh = sum / length;
  const double value = distribution_.D(wh) * fresnel_.reflectance(glm::dot(wo, wh)) *
                       g2_full_sphere(distribution_, wi, wo) / (4.0 * wo.z * wi.z);
  return std::isfinite(value) ? value : 0.0;
}

// Visible-normal sampling (Heitz 2018, "Sampling the GGX distribution of
// visible normals"): wh ~ D_wo(wh), wi the mirror of wo, with the reflection
// Jacobian d wh / d wi = 1 / (4 wo . wh) (Walter et al. 2007, eq. 14):
//   pdf(wi) = D_wo(wh) / (4 wo . wh),  value = F G2(wo, wi) / G1(wo).
std::optional<BsdfSample> RoughConductor::sample(const glm::dvec3& wo, double, const glm::dvec2& u,
                                                 RandomSequence&) const {
  if (wo.z <= 0.0) return std::nullopt;
  const glm::dvec3 wh = distribution_.sample_visible_normal(wo, u);
  const double cos_oh = glm::dot(wo, wh);
  if (cos_oh <= 0.0) return std::nullopt;
  const glm::dvec3 wi = reflect_about(wo, wh);
  if (wi.z <= 0.0) return std::nullopt;
  const double pdf = distribution_.visible_normal_pdf(wo, wh) / (4.0 * cos_oh);
  const double value =
      fresnel_.reflectance(cos_oh) * g2_full_sphere(distribution_, wi, wo) / distribution_.g1(wo);
  if (!(pdf > 0.0) || !std::isfinite(pdf) || !std::isfinite(value)) return std::nullopt;
  return BsdfSample{wi, value, pdf, kBsdfReflection | kBsdfGlossy};
}

double RoughConductor::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  const glm::dvec3 sum = wo + wi;
  const double length = glm::length(sum);
  if (length == 0.0) return 0.0;
  const glm::dvec3 wh = sum / length;
  const double cos_oh = glm::dot(wo, wh);
  if (cos_oh <= 0.0) return 0.0;
  const double pdf = distribution_.visible_normal_pdf(wo, wh) / (4.0 * cos_oh);
  return std::isfinite(pdf) ? pdf : 0.0;
}

}  // namespace skyfarm::material
