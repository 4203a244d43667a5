#include "common/material/surface_bsdf.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "common/material/direction_sampling.h"

namespace skyfarm::material {

std::optional<glm::dvec3> SurfaceBsdf::propose(const glm::dvec3& wo, double uc, const glm::dvec2& u) const {
  if (reflection_) {
    if (!(wo.z > 0.0)) return std::nullopt;
    const glm::dvec3 wi = uc < reflection_->cosine_share
                              ? sample_cosine_around({0.0, 0.0, 1.0}, u)
                              : reflect_about(wo, reflection_->distribution.sample_visible_normal(wo, u));
    if (!(wi.z > 0.0) || !(pdf(wo, wi) > 0.0)) return std::nullopt;
    return wi;
  }
  if (const auto* m = std::get_if<MultipleBounceBsdf>(&bsdf_)) return m->propose(wo, uc, u);
  RandomSequence unused(0);  // the exact forms draw nothing; rough diffuse's draws only feed its f
  const std::optional<BsdfSample> s = get().sample(wo, uc, u, unused);
  if (!s) return std::nullopt;
  return s->wi;
}

// Reflection-only: cosine_share cos / pi + (1 - cosine_share) D_wo(wh) /
// (4 wo.wh) (Walter et al. 2007, eq. 14, with the visible normals).
double SurfaceBsdf::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (!reflection_) return get().pdf(wo, wi);
  if (!(wo.z > 0.0) || !(wi.z > 0.0)) return 0.0;
  double lobe = 0.0;
  const glm::dvec3 sum = wo + wi;
  const double length = glm::length(sum);
  if (length > 0.0) {
    const glm::dvec3 wh = sum / length;
    const double cos_oh = glm::dot(wo, wh);
    if (cos_oh > 0.0) lobe = reflection_->distribution.visible_normal_pdf(wo, wh) / (4.0 * cos_oh);
  }
  const double pdf = reflection_->cosine_share * wi.z / kBsdfPi + (1.0 - reflection_->cosine_share) * lobe;
  return std::isfinite(pdf) ? pdf : 0.0;
}

}  // namespace skyfarm::material
