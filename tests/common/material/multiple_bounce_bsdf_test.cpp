// MultipleBounceBsdf::f is the two-way walk's estimate over |wo.z| for every
// facet kind (the same random numbers give the same value), with the
// arguments swapped into the walk's order (light from wi, seen from wo).
#include "common/material/multiple_bounce_bsdf.h"

#include <gtest/gtest.h>

#include <cmath>

namespace skyfarm::material {
namespace {

glm::dvec3 direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

TEST(MultipleBounceBsdf, EvaluatesTheTwoWayWalkForEveryFacetKind) {
  const MicrofacetDistribution dist(MicrofacetModel::ggx, 0.6, 0.6);
  const Facet facets[] = {Facet::conductor(ConductorFresnel::mirror()), Facet::diffuse(0.8), Facet::dielectric(1.5)};
  for (const Facet& facet : facets) {
    const MultipleBounceBsdf bsdf(dist, facet);
    glm::dvec3 wo = direction(0.9, 2.0);
    const glm::dvec3 wi = direction(0.4, 0.0);
    if (facet.kind == FacetKind::dielectric) wo.z = -wo.z;  // transmission
    RandomSequence a(77);
    RandomSequence b(77);
    double sum = 0.0;
    for (int i = 0; i < 200; ++i) {
      const double f = bsdf.f(wo, wi, a);
      EXPECT_EQ(f, bsdf.walk().estimate_bidirectional(wi, wo, b) / std::abs(wo.z));
      sum += f;
    }
    EXPECT_GT(sum, 0.0);
  }
}

}  // namespace
}  // namespace skyfarm::material
