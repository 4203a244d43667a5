// Every BSDF stays finite and non-negative at the edges of its parameters:
// near-mirror (alpha 1e-4) and very rough (alpha 1, 2) surfaces, grazing
// directions, total internal reflection, a dielectric-like conductor (k = 0)
// and an extreme one (k = 1e6).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "common/material/lambertian.h"
#include "common/material/multiple_bounce_bsdf.h"
#include "common/material/rough_conductor.h"
#include "common/material/rough_dielectric.h"
#include "common/material/rough_diffuse.h"

namespace skyfarm::material {
namespace {

std::vector<glm::dvec3> test_directions(bool two_sided) {
  std::vector<glm::dvec3> out;
  for (double z : {1.0, 0.9, 0.5, 1e-3, 1e-8}) {
    for (double phi : {0.0, 0.7, 2.5}) {
      const double r = std::sqrt(1.0 - z * z);
      out.push_back({r * std::cos(phi), r * std::sin(phi), z});
      if (two_sided) out.push_back({r * std::cos(phi), r * std::sin(phi), -z});
    }
  }
  return out;
}

void expect_stable(const std::string& name, const Bsdf& bsdf, bool two_sided) {
  SCOPED_TRACE(name);
  RandomSequence rng(3);
  const std::vector<glm::dvec3> dirs = test_directions(two_sided);
  for (const glm::dvec3& wo : dirs) {
    for (const glm::dvec3& wi : dirs) {
      const double f = bsdf.f(wo, wi, rng);
      const double pdf = bsdf.pdf(wo, wi);
      ASSERT_TRUE(std::isfinite(f) && f >= 0.0) << f;
      ASSERT_TRUE(std::isfinite(pdf) && pdf >= 0.0) << pdf;
    }
    for (int i = 0; i < 64; ++i) {
      const double uc = rng.next();
      const double u0 = rng.next();
      const double u1 = rng.next();
      if (const auto s = bsdf.sample(wo, uc, {u0, u1}, rng)) {
        ASSERT_TRUE(std::isfinite(s->value) && s->value >= 0.0) << s->value;
        ASSERT_TRUE(std::isfinite(s->pdf) && s->pdf > 0.0) << s->pdf;
        ASSERT_NEAR(glm::length(s->wi), 1.0, 1e-9);
      }
    }
  }
}

TEST(BsdfStability, FiniteAndNonNegativeEverywhere) {
  expect_stable("lambertian", Lambertian(1.0), false);
  const ConductorFresnel fresnels[] = {ConductorFresnel::mirror(), ConductorFresnel{{1.5, 0.0}, false},
                                       ConductorFresnel{{1.0, 1e6}, false}, ConductorFresnel{{0.05, 4.0}, false}};
  for (MicrofacetModel model : {MicrofacetModel::ggx, MicrofacetModel::beckmann}) {
    for (double alpha : {1e-4, 0.3, 1.0, 2.0}) {
      const MicrofacetDistribution dist(model, alpha, alpha);
      const MicrofacetDistribution aniso(model, alpha, std::max(1e-4, alpha * 0.1));
      const std::string tag = std::string(model == MicrofacetModel::ggx ? "ggx" : "beckmann") + " alpha " +
                              std::to_string(alpha);
      for (const ConductorFresnel& f : fresnels) {
        expect_stable("conductor " + tag, RoughConductor(dist, f), false);
        expect_stable("conductor aniso " + tag, RoughConductor(aniso, f), false);
      }
      for (double eta : {1.5, 1.0 / 1.5, 3.0}) {
        expect_stable("dielectric " + tag, RoughDielectric(dist, eta), true);
        expect_stable("dielectric importance " + tag, RoughDielectric(aniso, eta, TransportMode::importance), true);
      }
      expect_stable("rough diffuse " + tag, RoughDiffuse(aniso, 1.0), false);
      for (HeightCorrelation c : {HeightCorrelation::correlated, HeightCorrelation::uncorrelated}) {
        expect_stable("multiple conductor " + tag, MultipleBounceBsdf(aniso, Facet::conductor(fresnels[2]), c), false);
        expect_stable("multiple diffuse " + tag, MultipleBounceBsdf(dist, Facet::diffuse(1.0), c), false);
        expect_stable("multiple dielectric " + tag, MultipleBounceBsdf(aniso, Facet::dielectric(1.5), c), true);
      }
    }
  }
}

TEST(BsdfStability, RejectsInvalidParameters) {
  const MicrofacetDistribution dist(MicrofacetModel::ggx, 0.3, 0.3);
  EXPECT_THROW(Lambertian(1.5), std::invalid_argument);
  EXPECT_THROW(RoughDiffuse(dist, -0.1), std::invalid_argument);
  EXPECT_THROW(RoughDielectric(dist, 1.0), std::invalid_argument);
  EXPECT_THROW(RoughDielectric(dist, -2.0), std::invalid_argument);
  EXPECT_THROW(MultipleBounceBsdf(dist, Facet::dielectric(1.0)), std::invalid_argument);
  EXPECT_THROW(
      MultipleBounceBsdf(dist, Facet::conductor(ConductorFresnel::mirror()), HeightCorrelation::correlated, 1.0),
      std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm::material
