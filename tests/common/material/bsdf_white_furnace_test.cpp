// White furnace: surfaces whose facets absorb nothing keep all the energy
// once every bounce on the microsurface is counted, and lose the known
// multiple-scattering share when only the single bounce is.  The albedo for
// light from wi is integral f(wo, wi) |wo.z| dwo, estimated with wo drawn
// from the BSDF's own proposal around wi and f evaluated stochastically, so
// the test exercises f(), sample()'s proposal and pdf() together.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include <glm/geometric.hpp>

#include "common/material/multiple_bounce_bsdf.h"
#include "common/material/rough_conductor.h"
#include "common/material/rough_dielectric.h"
#include "common/material/smith_full_sphere.h"
#include "tests/common/material/sphere_quadrature.h"

namespace skyfarm::material {
namespace {

struct Estimate {
  double mean = 0.0;
  double standard_error = 0.0;
};

// integral f(wo, wi) |wo.z| dwo (restricted to orders by the walk when given).
// wo is drawn by `propose` (a direction with density bsdf.pdf(wi, .)).
template <class Propose>
Estimate albedo(const Bsdf& bsdf, const glm::dvec3& wi, int samples, std::uint64_t seed, Propose&& propose) {
  RandomSequence rng(seed);
  double sum = 0.0;
  double sum2 = 0.0;
  for (int i = 0; i < samples; ++i) {
    const double uc = rng.next();
    const double u0 = rng.next();
    const double u1 = rng.next();
    double x = 0.0;
    if (const std::optional<glm::dvec3> wo = propose(wi, uc, glm::dvec2(u0, u1), rng)) {
      x = bsdf.f(*wo, wi, rng) * std::abs(wo->z) / bsdf.pdf(wi, *wo);
    }
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / samples;
  return {mean, std::sqrt(std::max(sum2 / samples - mean * mean, 0.0) / samples)};
}

// The multiple-bounce BSDF's own proposal (no evaluation of f).
Estimate albedo(const MultipleBounceBsdf& bsdf, const glm::dvec3& wi, int samples, std::uint64_t seed) {
  return albedo(bsdf, wi, samples, seed,
                [&](const glm::dvec3& w, double uc, const glm::dvec2& u, RandomSequence&) {
                  return bsdf.propose(w, uc, u);
                });
}

// Any BSDF's sample() as the proposal.
Estimate albedo_by_sample(const Bsdf& bsdf, const glm::dvec3& wi, int samples, std::uint64_t seed) {
  return albedo(bsdf, wi, samples, seed,
                [&](const glm::dvec3& w, double uc, const glm::dvec2& u,
                    RandomSequence& rng) -> std::optional<glm::dvec3> {
                  const auto s = bsdf.sample(w, uc, u, rng);
                  if (!s) return std::nullopt;
                  return s->wi;
                });
}

const double kAlphas[] = {0.1, 0.5, 1.0, 2.0};

glm::dvec3 incidence(double theta) { return {std::sin(theta), 0.0, std::cos(theta)}; }

// The connection to wo after two or more bounces goes through the facet
// density seen from a random direction, which is peaked for smooth surfaces
// and makes f's estimate noisy (a standard deviation ~1.5-2 per sample at
// alpha 0.1 and 2): 800k samples give standard errors of 0.1-0.2 %.
TEST(BsdfWhiteFurnace, MirrorConductorKeepsAllEnergyWithMultipleBounces) {
  for (double alpha : kAlphas) {
    const MicrofacetDistribution dist(MicrofacetModel::ggx, alpha, alpha);
    const MultipleBounceBsdf bsdf(dist, Facet::conductor(ConductorFresnel::mirror()));
    const Estimate e = albedo(bsdf, incidence(0.7), 800000, 101);
    std::printf("mirror conductor alpha %.1f: albedo %.5f +- %.5f\n", alpha, e.mean, e.standard_error);
    EXPECT_NEAR(e.mean, 1.0, 0.005) << "alpha " << alpha;
  }
}

TEST(BsdfWhiteFurnace, WhiteRoughDiffuseKeepsAllEnergyWithMultipleBounces) {
  for (double alpha : kAlphas) {
    const MicrofacetDistribution dist(MicrofacetModel::ggx, alpha, alpha);
    const MultipleBounceBsdf bsdf(dist, Facet::diffuse(1.0));
    const Estimate e = albedo(bsdf, incidence(0.7), 300000, 202);
    std::printf("white rough diffuse alpha %.1f: albedo %.5f +- %.5f\n", alpha, e.mean, e.standard_error);
    EXPECT_NEAR(e.mean, 1.0, 0.005) << "alpha " << alpha;
  }
}

// The single bounce keeps E1(wi) = integral D_wi(wm) G2(wi, wo) / G1(wi) dwm
// (wo the mirror of wi; the visible normals whose mirror goes below are
// lost): the Monte Carlo albedo of the single-bounce BRDF matches that
// quadrature, it is < 1, and the multiple bounces (orders >= 2 of the walk)
// carry exactly the rest, 1 - E1.
TEST(BsdfWhiteFurnace, SingleBounceLosesTheMultipleScatteringShare) {
  const glm::dvec3 wi = incidence(0.7);
  for (double alpha : kAlphas) {
    const MicrofacetDistribution dist(MicrofacetModel::ggx, alpha, alpha);
    const double e1 = test::integrate_hemisphere(
        [&](const glm::dvec3& wm) {
          const glm::dvec3 wo = 2.0 * glm::dot(wi, wm) * wm - wi;
          if (wo.z <= 0.0) return 0.0;
          return dist.visible_normal_pdf(wi, wm) * g2_full_sphere(dist, wi, wo) / dist.g1(wi);
        },
        alpha, alpha, {wi});
    const RoughConductor single(dist, ConductorFresnel::mirror());
    const Estimate e = albedo_by_sample(single, wi, 100000, 303);
    EXPECT_LT(e1, 1.0);
    EXPECT_NEAR(e.mean, e1, 4.0 * e.standard_error + 1e-4) << "alpha " << alpha;

    const PositionFreeWalk walk(dist, Facet::conductor(ConductorFresnel::mirror()), HeightCorrelation::correlated);
    RandomSequence rng(404);
    double sum = 0.0;
    double sum2 = 0.0;
    constexpr int kSamples = 200000;
    for (int i = 0; i < kSamples; ++i) {
      // wo uniform on the hemisphere: pdf 1 / (2 pi).
      const double z = rng.next();
      const double phi = 2.0 * test::kPi * rng.next();
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      const double x = walk.estimate(wi, {r * std::cos(phi), r * std::sin(phi), z}, rng, 2) * 2.0 * test::kPi;
      sum += x;
      sum2 += x * x;
    }
    const double mean = sum / kSamples;
    const double se = std::sqrt((sum2 / kSamples - mean * mean) / kSamples);
    std::printf("alpha %.1f: single-bounce E1 %.5f (quadrature), %.5f +- %.5f (MC); "
                "orders >= 2 %.5f +- %.5f vs 1 - E1 %.5f\n",
                alpha, e1, e.mean, e.standard_error, mean, se, 1.0 - e1);
    EXPECT_NEAR(mean, 1.0 - e1, 4.0 * se + 1e-4) << "alpha " << alpha;
  }
}

// The first order of the walk is the single-bounce BRDF exactly (its
// connection is analytic for mirror facets).
TEST(BsdfWhiteFurnace, FirstOrderOfTheWalkIsTheSingleBounceBrdf) {
  const MicrofacetDistribution dist(MicrofacetModel::ggx, 0.4, 0.2);
  const ConductorFresnel gold{{0.43, 2.46}, false};
  const PositionFreeWalk walk(dist, Facet::conductor(gold), HeightCorrelation::correlated);
  const RoughConductor single(dist, gold);
  RandomSequence rng(5);
  for (int i = 0; i < 50; ++i) {
    const glm::dvec3 wi = glm::normalize(glm::dvec3(rng.next() - 0.5, rng.next() - 0.5, rng.next() + 0.05));
    const glm::dvec3 wo = glm::normalize(glm::dvec3(rng.next() - 0.5, rng.next() - 0.5, rng.next() + 0.05));
    const double expected = single.f(wo, wi, rng) * wo.z;
    EXPECT_NEAR(walk.estimate(wi, wo, rng, 1, 1), expected, 1e-12 * expected + 1e-300);
  }
}

// For dielectric facets too, reflection and refraction, light from either
// side: the first order is Walter et al.'s BSDF in radiance form (light from
// wi seen from wo), whose integral over wo is the flux kept.
TEST(BsdfWhiteFurnace, FirstOrderOfTheDielectricWalkIsTheSingleBounceBsdf) {
  const MicrofacetDistribution dist(MicrofacetModel::ggx, 0.5, 0.3);
  const PositionFreeWalk walk(dist, Facet::dielectric(1.5), HeightCorrelation::correlated);
  const RoughDielectric single(dist, 1.5, TransportMode::radiance);
  RandomSequence rng(6);
  int nonzero = 0;
  for (int i = 0; i < 400; ++i) {
    const glm::dvec3 wi = glm::normalize(glm::dvec3(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5));
    const glm::dvec3 wo = glm::normalize(glm::dvec3(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5));
    const double expected = single.f(wo, wi, rng) * std::abs(wo.z);
    if (expected > 0.0) ++nonzero;
    EXPECT_NEAR(walk.estimate(wi, wo, rng, 1, 1), expected, 1e-10 * expected + 1e-300)
        << "wi.z " << wi.z << " wo.z " << wo.z;
  }
  EXPECT_GT(nonzero, 200);
}

// The walk itself conserves energy exactly: with non-absorbing facets every
// walk leaves the surface (none reaches the bounce cap) carrying weight 1.
TEST(BsdfWhiteFurnace, EveryNonAbsorbingWalkLeavesWithAllItsEnergy) {
  for (double alpha : kAlphas) {
    const MicrofacetDistribution dist(MicrofacetModel::ggx, alpha, alpha * 0.5);
    for (const Facet& facet :
         {Facet::conductor(ConductorFresnel::mirror()), Facet::diffuse(1.0), Facet::dielectric(1.5)}) {
      for (HeightCorrelation c : {HeightCorrelation::correlated, HeightCorrelation::uncorrelated}) {
        const PositionFreeWalk walk(dist, facet, c);
        RandomSequence rng(606);
        for (int i = 0; i < 2000; ++i) {
          const auto exit = walk.trace(incidence(1.4), rng);
          ASSERT_TRUE(exit.has_value()) << "alpha " << alpha;
          ASSERT_EQ(exit->weight, 1.0);
          ASSERT_NEAR(glm::length(exit->direction), 1.0, 1e-9);
          if (facet.kind != FacetKind::dielectric) {
            ASSERT_GT(exit->direction.z, 0.0);
          }
        }
      }
    }
  }
}

// A non-absorbing dielectric reflects and transmits everything (flux over
// both hemispheres of wo, light from wi, from either side).
TEST(BsdfWhiteFurnace, DielectricReflectsPlusTransmitsEverything) {
  for (double alpha : kAlphas) {
    const MicrofacetDistribution dist(MicrofacetModel::ggx, alpha, alpha);
    const MultipleBounceBsdf bsdf(dist, Facet::dielectric(1.5));
    for (double z_sign : {1.0, -1.0}) {
      glm::dvec3 wi = incidence(0.7);
      wi.z *= z_sign;
      const Estimate e = albedo(bsdf, wi, 600000, 505);
      std::printf("dielectric alpha %.1f from %s: R + T %.5f +- %.5f\n", alpha, z_sign > 0 ? "outside" : "inside",
                  e.mean, e.standard_error);
      EXPECT_NEAR(e.mean, 1.0, std::max(0.005, 4.0 * e.standard_error)) << "alpha " << alpha << " side " << z_sign;
    }
  }
}

}  // namespace
}  // namespace skyfarm::material
