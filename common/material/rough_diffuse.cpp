#include "common/material/rough_diffuse.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "common/material/direction_sampling.h"
#include "common/material/smith_full_sphere.h"

namespace skyfarm::material {

RoughDiffuse::RoughDiffuse(const MicrofacetDistribution& distribution, double albedo)
    : distribution_(distribution), albedo_(albedo) {
  if (!(albedo >= 0.0 && albedo <= 1.0)) throw std::invalid_argument("RoughDiffuse: albedo outside [0, 1]");
}

// Heitz and Dupuy 2015, eq. 2 with the height-correlated G2:
//   f(wo, wi) = 1/|wi.z| integral D_wo(wm) (albedo / pi) <wi . wm>+ G2(wo, wi) / G1(wo) dwm,
// estimated with one wm ~ D_wo (the integral over the visible normals is the
// microsurface BRDF's, f_micro <wi . wm> D <wo . wm> G2 / (|wo.z| |wi.z|),
// rewritten with D_wo = G1(wo) <wo . wm> D / |wo.z|).
double RoughDiffuse::f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence& rng) const {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  const double u0 = rng.next();
  const double u1 = rng.next();
  const glm::dvec3 wm = distribution_.sample_visible_normal(wo, {u0, u1});
  const double cos_im = std::max(glm::dot(wi, wm), 0.0);
  const double value =
      albedo_ / kBsdfPi * cos_im * g2_full_sphere(distribution_, wi, wo) / (distribution_.g1(wo) * wi.z);
  return std::isfinite(value) ? value : 0.0;
}

std::optional<BsdfSample> RoughDiffuse::sample(const glm::dvec3& wo, double, const glm::dvec2& u,
                                               RandomSequence& rng) const {
  if (wo.z <= 0.0) return std::nullopt;
  const glm::dvec3 wi = sample_cosine_around({0.0, 0.0, 1.0}, u);
  if (wi.z <= 0.0) return std::nullopt;
  const double pdf = wi.z / kBsdfPi;
  return BsdfSample{wi, f(wo, wi, rng) * wi.z / pdf, pdf, kBsdfReflection | kBsdfDiffuse};
}

double RoughDiffuse::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  return wi.z / kBsdfPi;
}

}  // namespace skyfarm::material
